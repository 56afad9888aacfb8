#pragma once
/// @file
/// Replaying a recorded trajectory through the haptic renderer, streaming: a trajectory
/// source in, one row per servo tick out, memory independent of the number of ticks
/// (docs/spec.md, section 5b; docs/runtime.md, "Replay"). cfreplay and the Python package
/// are built on it:
///
///     auto poses = cf::TrajectoryCsvReader::open("poses.csv");
///     cf::Replay replay(graph, params, poses);
///     cf::ReplayRow row;
///     std::string line;
///     while (replay.next(row)) { line.clear(); cf::append_csv(row, line); ... }

#include <cf/graph.hpp>
#include <cf/params.hpp>
#include <cf/renderer.hpp>
#include <cf/types.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace cf {

/// One pose of a trajectory: where the device holds A at a time.
struct TrajectorySample {
  double t_s = 0;                       ///< s, increasing along a trajectory
  Pose X_WD;                            ///< device pose, mm; its rotation from the normalised q
  std::array<double, 4> q{1, 0, 0, 0};  ///< (qw, qx, qy, qz) as given, before normalising
  long line = 0;                        ///< 1-based line in its file, for messages; 0 if none
};

/// Where a replay's poses come from, one at a time.
class TrajectorySource {
 public:
  virtual ~TrajectorySource() = default;
  /// Writes the next sample into `sample`; false (and `sample` untouched) at the end.
  /// @throws cf::Error for a sample that is not a pose, naming where it is.
  virtual bool next(TrajectorySample& sample) = 0;
};

/// Samples held in memory (an application's recording, arrays from Python), given in order.
/// The replay checks their times.
class TrajectorySamples final : public TrajectorySource {
 public:
  /// @param samples  must outlive the source.
  explicit TrajectorySamples(const std::vector<TrajectorySample>& samples) : samples_(samples) {}
  bool next(TrajectorySample& sample) override {
    if (next_ == samples_.size()) return false;
    sample = samples_[next_++];
    return true;
  }

 private:
  const std::vector<TrajectorySample>& samples_;
  std::size_t next_ = 0;
};

/// POSES.csv (docs/spec.md, section 5b): the header `t,tx,ty,tz,qw,qx,qy,qz`, then one pose
/// per line (s, mm, unit quaternion of R_WA); blank lines and lines starting with '#' are
/// skipped; numbers are decimal, read in the "C" locale whatever the process's locale; a
/// quaternion within cf::kUnitQuaternionTolerance of norm 1 is normalised, others refused.
/// Read a buffer at a time: memory does not grow with the file.
class TrajectoryCsvReader final : public TrajectorySource {
 public:
  /// Opens `path` without blocking (a FIFO, a device or a directory is refused).
  /// @throws cf::FileError "PATH: cannot open the trajectory: <reason>".
  static TrajectoryCsvReader open(const std::string& path);
  /// Reads `text` held in memory; `source` names it in messages.
  TrajectoryCsvReader(std::string text, std::string source);
  ~TrajectoryCsvReader() override;
  TrajectoryCsvReader(TrajectoryCsvReader&&) noexcept;
  TrajectoryCsvReader& operator=(TrajectoryCsvReader&&) noexcept;

  /// @throws cf::Error "SOURCE:LINE: <reason>" for a missing or wrong header, a wrong
  ///   column count, a field that is not a finite decimal number, a non-unit quaternion, a
  ///   time that does not increase; at the end, for a file with no pose rows.
  bool next(TrajectorySample& sample) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One replayed tick, as cfreplay writes it (the text fields filled for the CSV).
struct ReplayRow {
  double t_s = 0;
  int cf = -1;              ///< the rendered CF's id, -1 when none
  std::string pcs;          ///< "type:a:b;..." (the contacts rendered conservatively when no CF)
  std::string motion;       ///< MT1..MT5, MT2.a/b/c, none
  Vec3 F_W = Vec3::Zero();  ///< N, the rendered force, world axes
  Vec3 M_W = Vec3::Zero();  ///< N mm, the rendered moment, world axes
  Vec3 F_A = Vec3::Zero();  ///< N, F_W in A's axes
  Vec3 M_A = Vec3::Zero();  ///< N mm, M_W in A's axes
  std::string status;       ///< cf::to_string(RenderStatus)
  /// The per-PC friction regimes joined by ';', then "approaching:PC" for each contact
  /// pushing by eq. (1) alone.
  std::string regimes;
  std::string discontinuities;  ///< cf::discontinuities_string of the tick
  Pose X_WD;                    ///< the device pose given to the tick
  Pose X_WP;                    ///< where A was rendered: the proxy pose (X_WD with the proxy off)
  Vec3 Fc_W = Vec3::Zero();     ///< N, what B exerts on A, world axes
  Vec3 Mc_W = Vec3::Zero();     ///< N mm, its moment about the reference point
};

/// Fills `row` from one renderer result, reusing its strings' storage.
void fill_replay_row(const HapticResult& result, ReplayRow& row);

/// The CSV header cfreplay writes (docs/spec.md, section 5b, columns first), no newline.
const char* replay_csv_header();
/// Appends `row` as one CSV line, no newline: times as their shortest round-trip decimal,
/// wrench components with 9 significant digits, in the "C" locale.
void append_csv(const ReplayRow& row, std::string& out);

/// The replay engine: steps a HapticRenderer at each pose the source gives. Holds one tick at
/// a time. Not thread-safe: one per thread.
class Replay {
 public:
  /// @param graph, source  must outlive the replay.
  /// @throws cf::Error when a parameter is out of range (cf::validate).
  Replay(const CfGraph& graph, const Params& params, TrajectorySource& source);
  ~Replay();
  Replay(Replay&&) noexcept;
  Replay& operator=(Replay&&) noexcept;

  /// Renders the source's next pose and fills `row`; false at the source's end.
  /// @throws cf::Error from the source, or "sample N (t = T s): time does not increase"
  ///   for a source that does not check its times itself.
  bool next(ReplayRow& row);
  /// The last tick's whole result (per-PC diagnostics, the proxy step); valid until the
  /// next call of next().
  /// @pre next() returned true at least once.
  const HapticResult& result() const;
  /// The last tick's sample. @pre next() returned true at least once.
  const TrajectorySample& sample() const;
  /// Ticks rendered so far.
  long ticks() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf
