#pragma once
// Writing an output whole or not at all without holding it in memory: the bytes are
// produced in pieces straight into the temporary file that is renamed into place
// (cf::write_outputs, cf/file_io.hpp, is this for bytes already in memory).

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace cf::internal {

/// Takes the next piece of an output's bytes.
using ByteSink = std::function<void(const char* data, std::size_t size)>;

/// One output: its path, and what writes its bytes into the sink it is given, in order.
struct StreamedOutput {
  std::string path;
  std::function<void(const ByteSink&)> produce;
};

/// write_outputs for outputs produced in pieces: the same checks of the paths against
/// `inputs`, each output written to a temporary file beside it, then all renamed into place.
/// A producer that throws leaves every target untouched (its exception goes on).
/// @throws cf::Error "<what> '<path>': <reason>".
void write_streamed_outputs(const std::vector<StreamedOutput>& files,
                            const std::vector<std::string>& inputs, const char* what);

}  // namespace cf::internal
