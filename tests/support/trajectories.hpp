#pragma once
// The bundled trajectories data/trajectories/*.csv (t,tx,ty,tz,qw,qx,qy,qz: s, mm, unit
// quaternion) as poses of A, for the tests and the benchmarks. Part of tests/support.

#include <cf/types.hpp>

#include <Eigen/Geometry>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace cf::testdata {

struct Tick {
  double t_s = 0;
  Pose X_WA;
};

/// Reads one trajectory file; its times are offset by t_offset_s.
/// @throws std::runtime_error naming the file when it cannot be read or a row is malformed.
inline std::vector<Tick> read_trajectory(const std::string& path, double t_offset_s = 0) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("read_trajectory: cannot open " + path);
  std::vector<Tick> out;
  std::string line;
  std::getline(in, line);  // header
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    double v[8];
    char c = 0;
    std::istringstream ss(line);
    ss >> v[0];
    for (int i = 1; i < 8; ++i) ss >> c >> v[i];
    if (!ss)
      throw std::runtime_error("read_trajectory: " + path + ":" + std::to_string(row) +
                               ": malformed row");
    Tick k;
    k.t_s = t_offset_s + v[0];
    k.X_WA.t_BA = {v[1], v[2], v[3]};
    k.X_WA.R_BA = Eigen::Quaterniond(v[4], v[5], v[6], v[7]).normalized().toRotationMatrix();
    out.push_back(k);
  }
  return out;
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
