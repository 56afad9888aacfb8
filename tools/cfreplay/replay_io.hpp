#pragma once
// cfreplay's files (docs/spec.md, section 5b): the trajectory CSV it reads, the force CSV and the
// SVG plot it writes. CGAL-free; linked into cfreplay and its tests.

#include <cf/types.hpp>

#include <array>
#include <string>
#include <vector>

namespace cf::replay {

/// One row of POSES.csv.
struct Sample {
  double t = 0;                         ///< s
  Pose pose;                            ///< its quaternion normalised
  std::array<double, 4> q{1, 0, 0, 0};  ///< (qw, qx, qy, qz) as read, before normalising
  int line = 0;                         ///< 1-based line in the file, for messages
};

/// Largest | |q| - 1 | accepted; such quaternions are normalised. Beyond it a row is not a
/// pose (a typo, or Euler angles written by mistake). The same for every tool
/// (cf::kUnitQuaternionTolerance): four significant digits.
constexpr double kQuaternionTolerance = 1e-3;

/// Reads POSES.csv: header `t,tx,ty,tz,qw,qx,qy,qz`, then one pose per line; blank lines
/// and lines starting with '#' are skipped.
/// @throws cf::Error "FILE:LINE: reason" for a missing file, a wrong header, a wrong column
///   count, a field that is not a finite number, a non-unit quaternion, a time that does not
///   increase, or no rows at all.
std::vector<Sample> read_trajectory(const std::string& path);
/// The same from text (`source` names it in messages).
std::vector<Sample> parse_trajectory(const std::string& text, const std::string& source);

/// One output row (world frame first, then A-frame columns, then diagnostics).
struct Row {
  double t = 0;
  int cf = -1;
  std::string pcs;     ///< "type:a:b;..."
  std::string motion;  ///< MT1..MT5, MT2.a/b/c, none
  Vec3 F_W = Vec3::Zero(), M_W = Vec3::Zero(), F_A = Vec3::Zero(), M_A = Vec3::Zero();
  std::string status;   ///< identification / rendering status
  std::string regimes;  ///< per-PC friction regimes joined by ';'
  /// the force model's discontinuities by design at this tick (cf::discontinuities_string)
  std::string discontinuities;
  Pose X_WP;  ///< where A was rendered: the proxy pose (the device pose without it)
  /// What B exerts on A (eqs. (1)-(8) plus the proxy's constraint forces), about the
  /// moment's reference point, world axes.
  Vec3 Fc_W = Vec3::Zero(), Mc_W = Vec3::Zero();
};

/// The output header (the columns of section 5b of docs/spec.md first).
const char* output_header();
/// Formats one row (no newline).
std::string format_row(const Row& row);

/// Writes `text` to `path` through a temporary file in the same directory and a rename, so
/// the file is whole or absent; refuses a device, FIFO or directory and any of `inputs`.
/// @throws cf::Error naming the file.
void write_file_atomic(const std::string& path, const std::string& text,
                       const std::vector<std::string>& inputs = {});

/// An SVG of force and moment components against time, with background bands labelled
/// with the CF id and the motion type of each run of equal (cf, motion): the rendered wrench
/// in full lines, the contact wrench dashed.
std::string svg_plot(const std::vector<Row>& rows, const std::string& title);

}  // namespace cf::replay
