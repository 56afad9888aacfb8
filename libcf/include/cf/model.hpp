#pragma once
/// @file
/// The immutable half of the run time (after MuJoCo's `mjModel`): a CF graph with its two
/// polyhedra, the contact detector's trees and tables, and the parameters. Built once per
/// model pair; shared read-only by any number of servo threads, each with its own CfState
/// (cf/state.hpp). The stages that use it are in cf/servo.hpp.

#include <cf/graph.hpp>
#include <cf/params.hpp>
#include <cf/polyhedron.hpp>

#include <memory>

namespace cf {

namespace internal {
struct Access;
}

/// Everything the servo loop reads and never writes. Thread-safe to share once built.
class CfModel {
 public:
  /// Builds detection's trees and tables for the graph's models (copied into the model).
  /// @param graph  must outlive the model and every state made from it.
  /// @throws cf::Error when a parameter is out of range (validate(), cf/params.hpp).
  explicit CfModel(const CfGraph& graph, const Params& params = {});
  ~CfModel();
  CfModel(CfModel&&) noexcept;
  CfModel& operator=(CfModel&&) noexcept;
  CfModel(const CfModel&) = delete;
  CfModel& operator=(const CfModel&) = delete;

  const CfGraph& graph() const;
  const Params& params() const;
  const Polyhedron& model_a() const;  ///< A, the moving polyhedron (the graph's)
  const Polyhedron& model_b() const;  ///< B, the fixed one

  struct Impl;

 private:
  friend struct internal::Access;
  std::unique_ptr<const Impl> impl_;
};

}  // namespace cf
