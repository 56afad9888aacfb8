#pragma once
// Finishing a detection's contacts: canonical order, dominance (the PC rule of docs/spec.md,
// section 4) and contact planes. One free function over the contacts the exact tests emitted; what
// it reads of the model pair and the parameters is passed in, its scratch is the caller's.

#include <cf/contact.hpp>
#include <cf/polyhedron.hpp>

#include <array>
#include <cstdint>

namespace cf::internal {

/// What finishing reads: the models (closures of elements), the thresholds.
struct FinishContext {
  const Polyhedron* a = nullptr;
  const Polyhedron* b = nullptr;
  double epsilon_mm = 1;
  double dominance_fit = 0.25;     ///< DetectionParams::dominance_fit
  double dominance_penalty = 1;    ///< DetectionParams::dominance_penalty
  double cos_plane_tolerance = 1;  ///< cos of the largest angular tolerance: one contact plane
  bool small_indices = false;      ///< every element index fits the sort keys' 24 bits
};

/// Scratch of finish_contacts, sized once: it allocates nothing.
struct FinishScratch {
  std::array<std::uint64_t, ContactSet::kCapacity> sort_keys{};
  std::array<ContactPc, ContactSet::kCapacity> sort_buf{};
  /// Per type of PC that can dominate (f-f, e-f, f-e), the contacts of that type that fit
  /// well enough to.
  std::array<std::array<int, ContactSet::kCapacity>, 3> dominators{};
  std::array<int, ContactSet::kCapacity> reps{};  ///< first member of each plane group
  /// The contacts that weigh in a plane's centre (fit * (epsilon - distance) > 0), and that
  /// weight, in contact order.
  std::array<int, ContactSet::kCapacity> weighted{};
  std::array<double, ContactSet::kCapacity> weight{};
};

/// Sorts `cs` by PC, sets `dominated` (adding the penalty to those misfits), groups the
/// contacts into contact planes (`plane`, `num_planes`) and sets each one's `centre_W`.
void finish_contacts(const FinishContext& ctx, FinishScratch& scratch, ContactSet& cs);

}  // namespace cf::internal
