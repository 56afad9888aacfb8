#pragma once
/// @file
/// Reading input files and writing output files the way section 5b of docs/spec.md requires, and
/// the checks every cf tool applies to what it reads (quaternions, model sizes). libcf's graph
/// reading and writing use it; so do the tools, through this public header.
///
/// - Reading never blocks: the file is opened non-blocking and anything that is not a
///   regular file (a FIFO, a device, a directory, a socket) is refused before a byte is read.
/// - Output files are written whole or not at all (a temporary file in the target's
///   directory, fsync, rename), never over one of the run's inputs; an output path that is a
///   device, a FIFO, a socket or a directory is refused; a symlink is followed and its
///   target replaced (the link stays a link).
/// - Text from a file that goes into a message is made printable first.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace cf {

class Polyhedron;

/// Bytes of capacity read_input_file leaves past the end of what it read.
inline constexpr std::size_t kReadSlack = 64;

/// Reads the whole of `path`. On failure returns false with `why` set to a short reason
/// ("no such file", "is a directory, not a regular file", "is a FIFO (named pipe), not a
/// regular file", "permission denied", "larger than 2 GiB"), without the file name. On
/// success `bytes.capacity()` exceeds `bytes.size()` by at least kReadSlack.
bool read_input_file(const std::string& path, std::string& bytes, std::string& why,
                     std::size_t max_bytes = std::size_t{1} << 31);

/// One file to write.
struct OutputFile {
  std::string path;
  std::string bytes;
};

/// Checks that `path` can be an output of a run that reads `inputs` and writes `outputs`
/// besides it: not empty, not naming a directory, not a device, FIFO, socket or directory
/// (after following symlinks), not the same file as an input or as another output (also
/// when none exists yet: "o.csv" and "./o.csv" are one file), its name no longer than the
/// file system takes. Call it before the work, so that a bad path fails fast; the writers
/// below check again.
/// @throws cf::Error "<what> '<path>': <reason>".
void check_output_path(const std::string& path, const std::vector<std::string>& inputs,
                       const char* what, const std::vector<std::string>& outputs = {});

/// The absolute path `path` names, symlinks and "." / ".." resolved as far as the path
/// exists, the rest normalised: equal for two paths that name one file, existing or not.
std::string canonical_path(const std::string& path);

/// Writes every file whole, or none of them: all the temporary files are written and synced
/// first, then renamed into place (symlinks followed). Two outputs naming the same file are
/// refused. An existing target keeps its permission bits.
/// @throws cf::Error "<what> '<path>': <reason>"; no temporary file is left behind.
void write_outputs(const std::vector<OutputFile>& files, const std::vector<std::string>& inputs,
                   const char* what);

/// Takes the next piece of an output's bytes.
using ByteSink = std::function<void(const char* data, std::size_t size)>;

/// One output produced in pieces: its path, and what writes its bytes, in order, into the
/// sink it is given.
struct StreamedOutput {
  std::string path;
  std::function<void(const ByteSink&)> produce;
};

/// write_outputs for outputs too large to hold in memory (a replay of millions of ticks, a
/// graph): the same checks of the paths, each output produced straight into a temporary
/// file beside it, in the order given, then all renamed into place. A producer that throws
/// leaves every target untouched (its exception goes on).
/// @throws cf::Error "<what> '<path>': <reason>".
void write_streamed_outputs(const std::vector<StreamedOutput>& files,
                            const std::vector<std::string>& inputs, const char* what);

/// `text` with every byte that is not printable ASCII written as \xHH, cut to `max` bytes
/// of input (then "..."), for quoting file content in a one-line message.
std::string printable(const std::string& text, std::size_t max = 60);

/// One tolerance for a quaternion typed or read by any tool (docs/spec.md, section 5b): within 1e-3
/// of norm 1 (four significant digits) it is accepted and normalised, beyond it refused.
constexpr double kUnitQuaternionTolerance = 1e-3;

/// Empty when | |q| - 1 | <= kUnitQuaternionTolerance (and q finite), else the reason with
/// the norm: "the quaternion (qw,qx,qy,qz) has norm 1.00498756, not 1 within 0.001".
std::string quaternion_problem(double w, double x, double y, double z);

/// Below this many epsilon across (bounding-box diagonal) a model is small against the
/// contact threshold, above kLargeModel epsilon it is large (docs/spec.md, section 2: a model whose
/// unit was not given may be in metres, or in micrometres).
constexpr double kSmallModel = 10;
constexpr double kLargeModel = 1e5;

/// Empty when `model` is a reasonable size against `epsilon_mm`, else a warning naming the
/// sizes: "model A 'cube' is 0.0173 mm across (bounding-box diagonal), small against the
/// contact threshold epsilon = 1 mm". The caller adds what the user can do about it.
std::string size_warning(const Polyhedron& model, const std::string& which, double epsilon_mm);

}  // namespace cf
