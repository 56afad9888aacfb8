#pragma once
/// @file
/// Basic value types shared by every part of libcf: vectors, poses and typed ids.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>

namespace cf {

using Vec3 = Eigen::Vector3d;  ///< mm unless a name or comment says otherwise
using Mat3 = Eigen::Matrix3d;

/// Rigid pose of A in B's (the world's) frame: x_B = R_BA * x_A + t_BA (docs/spec.md, section 2).
struct Pose {
  Mat3 R_BA = Mat3::Identity();  ///< rotation taking A-frame vectors to B-frame vectors
  Vec3 t_BA = Vec3::Zero();      ///< mm, A's origin in B's frame

  /// Maps a point given in A's frame to B's frame.
  Vec3 apply(const Vec3& p_A) const { return R_BA * p_A + t_BA; }
  /// Maps a point given in B's frame to A's frame.
  Vec3 inverse_apply(const Vec3& p_B) const { return R_BA.transpose() * (p_B - t_BA); }
};

/// A typed index, so that a vertex index cannot be passed where a face index is expected
/// (Drake's Identifier idea). -1 means "none".
template <class Tag>
class Id {
 public:
  constexpr Id() = default;
  constexpr explicit Id(std::int32_t value) : value_(value) {}
  constexpr std::int32_t value() const { return value_; }
  constexpr std::size_t index() const { return static_cast<std::size_t>(value_); }
  constexpr bool valid() const { return value_ >= 0; }
  friend constexpr bool operator==(Id a, Id b) { return a.value_ == b.value_; }
  friend constexpr bool operator!=(Id a, Id b) { return a.value_ != b.value_; }
  friend constexpr bool operator<(Id a, Id b) { return a.value_ < b.value_; }

 private:
  std::int32_t value_ = -1;
};

using VertexId = Id<struct VertexTag>;
using EdgeId = Id<struct EdgeTag>;
using FaceId = Id<struct FaceTag>;

/// Thrown for bad user input (files, parameters). The message names the operation, the
/// reason, the offending value and where it was found (file, line, JSON pointer).
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An Error about a file as such: it cannot be opened or read (missing, a FIFO, a device, a
/// directory, too large), or an output cannot be written there (an input of the run, a
/// special file, no such directory, a failed write). Python raises it as cf.FileError, both
/// a cf.Error and an OSError.
class FileError : public Error {
 public:
  using Error::Error;
};

}  // namespace cf

template <class Tag>
struct std::hash<cf::Id<Tag>> {
  std::size_t operator()(cf::Id<Tag> id) const noexcept {
    return std::hash<std::int32_t>()(id.value());
  }
};
