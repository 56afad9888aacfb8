#pragma once
// The bundled trajectories data/trajectories/*.csv (t,tx,ty,tz,qw,qx,qy,qz: s, mm, unit
// quaternion) as poses of A, and replays of them, for the tests and the benchmarks. Part of
// tests/support.

#include <cf/replay.hpp>
#include <cf/types.hpp>

#include <functional>
#include <string>
#include <vector>

namespace cf::testdata {

struct Tick {
  double t_s = 0;
  Pose X_WA;
};

/// Reads one trajectory file with libcf's reader; its times are offset by t_offset_s.
/// @throws cf::Error naming the file and line when it cannot be read or a row is malformed.
inline std::vector<Tick> read_trajectory(const std::string& path, double t_offset_s = 0) {
  std::vector<Tick> out;
  TrajectoryCsvReader reader = TrajectoryCsvReader::open(path);
  TrajectorySample s;
  while (reader.next(s)) out.push_back({t_offset_s + s.t_s, s.X_WD});
  return out;
}

/// Every sample of a trajectory file, as read (libcf's reader).
inline std::vector<TrajectorySample> read_samples(const std::string& path) {
  std::vector<TrajectorySample> out;
  TrajectoryCsvReader reader = TrajectoryCsvReader::open(path);
  TrajectorySample s;
  while (reader.next(s)) out.push_back(s);
  return out;
}

/// Every row of a replay of `samples` (cf::Replay); `each`, when given, sees each tick's sample
/// and whole result.
inline std::vector<ReplayRow> replay_rows(
    const CfGraph& graph, const std::vector<TrajectorySample>& samples, const Params& params,
    const std::function<void(const TrajectorySample&, const HapticResult&)>& each = {}) {
  TrajectorySamples source(samples);
  Replay replay(graph, params, source);
  std::vector<ReplayRow> rows;
  ReplayRow row;
  while (replay.next(row)) {
    if (each) each(replay.sample(), replay.result());
    rows.push_back(row);
  }
  return rows;
}

/// data/trajectories/cube_lblock_{guarded,slide,corner,rotate,break}.csv played back to back
/// (7,405 ticks; each file's times follow the previous file's last by 1 ms).
inline std::vector<Tick> cube_lblock_ticks(const std::string& source_dir) {
  std::vector<Tick> out;
  double t_off = 0;
  for (const char* name : {"guarded", "slide", "corner", "rotate", "break"}) {
    const std::vector<Tick> part =
        read_trajectory(source_dir + "/data/trajectories/cube_lblock_" + name + ".csv", t_off);
    out.insert(out.end(), part.begin(), part.end());
    if (!part.empty()) t_off = part.back().t_s + 0.001;
  }
  return out;
}

}  // namespace cf::testdata
