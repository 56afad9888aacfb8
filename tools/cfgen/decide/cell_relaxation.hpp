#pragma once
/// @file
/// What every pose with its rotation in a cell must meet for the PCs of a set to hold at once
/// (docs/generator.md, "Deciding a set"): each contact at a point of both closed elements,
/// the rotational conditions (an f-f's normals opposite, an e-f's or f-e's edge parallel to
/// the face) and local non-penetration at each contact, with every quantity the rotation
/// moves widened by the cell's turn bound. The rest of the two solids is left out. It is a
/// relaxation: a cell it refutes holds no pose at which the set's PCs hold, and the
/// refutation names the condition that failed or carries Farkas certificates.

#include "cfgen/decide/rotation_cells.hpp"
#include "cfgen/verify/analysis.hpp"
#include "cfgen/verify/lp.hpp"
#include "cfgen/verify/rotation_conditions.hpp"

#include <cf/pc.hpp>

#include <optional>
#include <vector>

namespace cf::gen {

class CellRelaxation {
 public:
  /// a, b: the analyses of A and B, which must outlive this object. At most 3 PCs.
  /// touch_tol (mm): elements this close touch (SearchParams::touch_tol); every contact row
  /// is widened by it, so poses the verifier counts as touching stay in the relaxation.
  /// margin (mm): each contact point at least this far inside its elements (from an edge's
  /// ends, from a face's boundary within its plane); 0 for the closed elements. With the
  /// verifier's min_margin, a refutation shows that no witness exists (every witness has
  /// its contacts that far inside, Verifier::contact_margin), not that no pose realises
  /// the set.
  /// local_slack (a sine): the local non-penetration margin each pose must keep
  /// (local_margin_bound); with the verifier's verified_local_slack(), as with min_margin, a
  /// refutation shows that no witness exists. 0: only penetration refutes.
  /// rot_tol (rad): what a pose may leave of a rotational condition (kRotAccepted for a
  /// witness; more for a set decided for its images under the models' symmetries).
  CellRelaxation(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs, double touch_tol,
                 double margin = 0, double local_slack = 0, double rot_tol = kRotAccepted);

  /// Why a cell holds no pose of the set.
  enum class Verdict {
    kOpen,        // not refuted: some pose of the relaxation may have its rotation here
    kBounds,      // the PCs' contact points cannot be near enough for any rotation
    kRotation,    // a PC's rotational condition misses by more than the turn bound (pc)
    kCone,        // a PC is locally penetrating for every rotation of the cell (pc, direction)
    kSlack,       // a PC's local margin is below local_slack for every rotation of the cell (pc)
    kFirstOrder,  // the PCs' local margins to first order (first_order.hpp) cannot all reach
                  // local_slack in the cube: `certificates`, one per choice of e-e signs
    kProgram,     // the translation programs of every choice of convex pieces are infeasible
    kDeep,        // a point of one solid lies inside the other at every pose (DeepPoints)
  };
  /// A part of the given translation box cut off when an open cell's box is narrowed, with
  /// the proof that no choice of pieces has a solution there.
  struct Slab {
    Vec3 lo, hi;                            // mm
    std::vector<FarkasCertificate> proofs;  // one per choice, in choice order
  };
  struct Refutation {
    Verdict verdict = Verdict::kOpen;
    int pc = -1;  // kRotation, kCone, kSlack: the PC's index in the set
    /// kCone: the tangent direction that enters the face (unit, in its own solid's frame:
    /// A's for a v-f or e-f, B's for an f-v or f-e).
    Vec3 direction = Vec3::Zero();
    /// kProgram with certificates asked for: one per choice of pieces, in choice order
    /// (choice_list() gives the choices).
    std::vector<FarkasCertificate> certificates;
    /// kOpen with certificates asked for: the slabs the narrowing cut off, tiling the given
    /// box with the narrowed one.
    std::vector<Slab> slabs;
    /// kOpen: the local margin is unsettled over the cell (its bound exceeds its value at the
    /// centre by at least as much as the centre exceeds local_slack), so the box was kept as
    /// given; only when refute's may_keep_box allowed it.
    bool unsettled = false;
  };
  /// Whether some pose with its rotation in the cell and A's pivot at a translation in
  /// [t_lo, t_hi] (mm, B's frame) can meet the relaxation. When the cell stays open, t_lo and
  /// t_hi are narrowed to the translations the feasible programs allow (grown by 1e-7 of the
  /// models' size for the solver's tolerances), a side only where the slab it cuts off is
  /// proven empty (Farkas certificates). Choices of convex pieces beyond max_choices leave
  /// the cell open.
  Refutation refute(const RotationCell& cell, Vec3& t_lo, Vec3& t_hi, bool with_certificates,
                    std::size_t max_choices = 4096) const;
  /// The same for the rotations that turn A's vectors at most `turn` from where R_c does.
  /// may_keep_box: an open cell whose local margin is unsettled keeps [t_lo, t_hi] as given
  /// (one program a choice instead of thirteen) and says so (Refutation::unsettled), for a
  /// caller that splits such a cell over its rotations anyway.
  Refutation refute(const Mat3& R_c, const TurnBound& turn, Vec3& t_lo, Vec3& t_hi,
                    bool with_certificates, std::size_t max_choices = 4096,
                    bool may_keep_box = false) const;

  /// True when at rotation R (meeting the rotational conditions to 10 kRotTol) the contacts
  /// can hold in their closed elements without local penetration: the relaxation holds at a
  /// pose, which therefore proves nothing about the set.
  bool holds_at(const Mat3& R) const;

  /// The program over the translation and the contacts' parameters at the centre rotation R_c
  /// of a set of rotations that turn A's vectors at most `turn`, for one choice of convex pieces
  /// (an index per face slot, slot_sizes() order): rows a . x <= b, every variable bounded. The
  /// translation of the pivot is bounded by [t_lo, t_hi].
  LinearProgram program(const Mat3& R_c, const TurnBound& turn, const std::vector<int>& choice,
                        const Vec3& t_lo, const Vec3& t_hi) const;
  /// mm, B's frame: the translations of the pivot any pose of the set can have (each PC's
  /// element of B grown by how far its element of A reaches from the pivot).
  const Vec3& t_lo() const { return t_lo_; }
  const Vec3& t_hi() const { return t_hi_; }
  /// Convex pieces of each face slot: A's face then B's face of each PC that has them.
  const std::vector<int>& slot_sizes() const { return slot_sizes_; }
  /// Choices of convex pieces: the product of slot_sizes().
  std::size_t choices() const;
  /// Every choice, in the order refute() tries them (the first slot counting fastest).
  std::vector<std::vector<int>> choice_list() const;
  /// mm, A's frame: the point the cell's rotations turn A about (the centroid of the PCs'
  /// elements of A); the program's translation is where it goes.
  const Vec3& pivot() const { return pivot_; }

 private:
  struct Side {  // one element of a PC
    ElementKind kind;
    int index;
  };
  // slack_bound: when given and the slack is tested, the local margin's bound over the cell.
  Verdict rotation_test(const Mat3& R_c, const TurnBound& turn, int& pc, Vec3& direction,
                        double* slack_bound = nullptr) const;
  std::vector<Slab> narrow(const Mat3& R_c, const TurnBound& turn, Vec3& t_lo, Vec3& t_hi,
                           const Vec3& lo, const Vec3& hi) const;
  void add_contact(LinearProgram& lp, int pc, const Mat3& R_c, const TurnBound& turn, int& slot,
                   const std::vector<int>& choice) const;

  const ModelInfo& A_;
  const ModelInfo& B_;
  PcSet pcs_;
  Vec3 pivot_ = Vec3::Zero();
  std::vector<int> slot_sizes_;
  double size_ = 0;         // mm, the larger model's bounding-box diagonal
  double touch_tol_ = 0;    // mm
  double margin_ = 0;       // mm
  double local_slack_ = 0;  // sine
  double rot_tol_ = 0;      // rad
  Vec3 t_lo_, t_hi_;        // mm: bounds of the translation every PC allows
  bool empty_ = false;
};

}  // namespace cf::gen
