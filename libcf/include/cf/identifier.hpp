#pragma once
/// @file
/// Run-time CF identification (docs/spec.md, section 6; paper section 4.1): detect the candidate
/// PCs at a pose and choose among their consistent interpretations a PC set that is a CF of the
/// graph, preferring the previous CF, then a graph neighbour of it, then the best geometric fit.
/// Bounded time, no heap allocation per step. docs/runtime.md describes the rules.

#include <cf/contact.hpp>
#include <cf/graph.hpp>
#include <cf/params.hpp>

#include <array>
#include <cstdint>
#include <memory>

namespace cf {

/// Outcome of one identification step.
enum class IdStatus : std::uint8_t {
  kMatchedPrevious,   ///< the previous CF still explains the contacts (MT2)
  kMatchedNeighbour,  ///< a graph neighbour of the previous CF (MT3-MT5)
  kMatchedByFit,      ///< no previous CF (first contact): the best geometric fit
  kNoContact,         ///< nothing within epsilon
  /// A CF of the graph fits, but it is neither the previous CF nor its neighbour (a jump,
  /// e.g. fast motion). `cf` is set to the best fit; callers may treat it with caution.
  kNonNeighbourJump,
  kOutsideGraph,   ///< contacts detected, but no interpretation is a CF of the graph
  kTooManyPlanes,  ///< more than 3 contact planes and no subset explains them
};
/// "matched-previous", "matched-neighbour", "matched-by-fit", "no-contact",
/// "non-neighbour-jump", "outside-graph", "too-many-planes".
const char* to_string(IdStatus status);

/// Result of CfIdentifier::step. Fixed capacity; lives inside the identifier.
struct Identification {
  IdStatus status = IdStatus::kNoContact;
  CfId cf;    ///< the identified CF; invalid when none fits or no contact
  PcSet pcs;  ///< its PCs (canonical order); empty when cf is invalid
  /// The CF's PCs with geometry, in the order of `pcs`; num_cf_pcs entries are valid.
  std::array<ContactPc, PcSet::kMaxPcs> cf_pcs{};
  int num_cf_pcs = 0;
  /// Every candidate detected at this pose (capacity ContactSet::kCapacity, overflow flagged).
  ContactSet contacts;
  double misfit = 0;     ///< total misfit of the chosen interpretation
  int combinations = 0;  ///< interpretations examined
  bool capped = false;   ///< the enumeration hit max_combinations
  /// True when the chosen CF does not cover every contact plane: the other planes' contacts
  /// are apart (farther than every PC of the CF, and than touch_distance_mm) or alternative
  /// readings of the chosen PCs (degenerate touches).
  bool partial_cover = false;
  /// Contacts approaching within epsilon that the CF leaves apart: of each contact plane
  /// the CF does not hold and whose contacts are all apart, the nearest one (best fit among
  /// equals). A renderer gives them eq. (1)'s normal force so that the force does not step
  /// when they are gained (docs/force-model.md). Empty when no CF was identified.
  std::array<ContactPc, 8> approaching{};
  int num_approaching = 0;
  bool has_cf() const { return cf.valid(); }
};

/// Identifies the CF at each servo tick: cf::detect and cf::identify on its own CfModel and
/// CfState, the previous CF advancing as cf::classify_motion advances it. Create one per
/// thread; the graph is shared, read-only, and must outlive the identifier.
class CfIdentifier {
 public:
  /// Uses `params.epsilon_mm`, `params.detection` and `params.identification`.
  /// @throws cf::Error when a parameter is out of range (validate(), cf/params.hpp).
  explicit CfIdentifier(const CfGraph& graph, const Params& params = {});
  ~CfIdentifier();
  CfIdentifier(CfIdentifier&&) noexcept;
  CfIdentifier& operator=(CfIdentifier&&) noexcept;

  /// Detects and identifies at `pose`. No heap allocation. The reference stays valid until
  /// the next step or reset.
  const Identification& step(const Pose& pose);
  /// Forgets the previous CF (the next match is by fit).
  void reset();
  /// The CF preferred at the next step: the last identified CF, kept across ticks whose
  /// contacts fit no CF, cleared when there is no contact.
  CfId previous() const;
  const Identification& last() const;
  const CfGraph& graph() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf
