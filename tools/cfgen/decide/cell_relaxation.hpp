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

#include <cf/pc.hpp>

#include <optional>
#include <vector>

namespace cf::gen {

class CellRelaxation {
 public:
  /// a, b: the analyses of A and B, which must outlive this object. At most 3 PCs.
  CellRelaxation(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs);

  /// Why a cell holds no pose of the set.
  enum class Verdict {
    kOpen,      // not refuted: some pose of the relaxation may have its rotation here
    kBounds,    // the PCs' contact points cannot be near enough for any rotation
    kRotation,  // a PC's rotational condition misses by more than the turn bound (pc)
    kCone,      // a PC is locally penetrating for every rotation of the cell (pc)
    kProgram,   // the translation programs of every choice of convex pieces are infeasible
  };
  struct Refutation {
    Verdict verdict = Verdict::kOpen;
    int pc = -1;  // kRotation, kCone: the PC's index in the set
    /// kProgram with certificates asked for: one per choice of pieces, in choice order.
    std::vector<FarkasCertificate> certificates;
  };
  /// Whether the cell holds a rotation at which the relaxation can hold. Choices of convex
  /// pieces beyond max_choices leave the cell open.
  Refutation refute(const RotationCell& cell, bool with_certificates,
                    std::size_t max_choices = 4096) const;

  /// True when at rotation R (meeting the rotational conditions to 10 kRotTol) the contacts
  /// can hold in their closed elements without local penetration: the relaxation holds at a
  /// pose, which therefore proves nothing about the set.
  bool holds_at(const Mat3& R) const;

  /// The program over the translation and the contacts' parameters at the centre rotation R_c
  /// of a cell with turn bound beta, for one choice of convex pieces (an index per face slot,
  /// slot_sizes() order): rows a . x <= b, every variable bounded.
  LinearProgram program(const Mat3& R_c, double beta, const std::vector<int>& choice) const;
  /// Convex pieces of each face slot: A's face then B's face of each PC that has them.
  const std::vector<int>& slot_sizes() const { return slot_sizes_; }
  /// mm, A's frame: the point the cell's rotations turn A about (the centroid of the PCs'
  /// elements of A); the program's translation is where it goes.
  const Vec3& pivot() const { return pivot_; }

 private:
  struct Side {  // one element of a PC
    ElementKind kind;
    int index;
  };
  Verdict rotation_test(const Mat3& R_c, double beta, int& pc) const;
  void add_contact(LinearProgram& lp, int pc, const Mat3& R_c, double beta, int& slot,
                   const std::vector<int>& choice) const;

  const ModelInfo& A_;
  const ModelInfo& B_;
  PcSet pcs_;
  Vec3 pivot_ = Vec3::Zero();
  std::vector<int> slot_sizes_;
  Vec3 t_lo_, t_hi_;  // mm: bounds of the translation every PC allows
  bool empty_ = false;
};

}  // namespace cf::gen
