#pragma once
/// @file
/// The local margins of a set's PCs to first order over a cube of rotations (docs/generator.md,
/// "Refuting a set over cells of poses"; docs/certificates.md, "First-order leaves"). Every
/// rotation R of a cube is R_c Q, Q a turn by an angle theta <= theta_max about an axis w
/// (Hartley and Kahl 2009), and Q x = x + v x x + E(x) with v = sin(theta) w and
/// |E(x)| <= (1 - cos theta_max) |x|. Each term of the verifier's local margin (a turned
/// vector against a fixed one, or an e-e's normal against a wedge) is then an affine function
/// of v plus a bounded remainder, and so are the rotational conditions of `e-f` and `f-e`.
/// Where no v in the box |v_k| <= sin theta_max meets every term at the slack (a program
/// over v, infeasible by Farkas multipliers), no rotation of the cube has every PC at the
/// slack. Unlike the terms bounded one at a time, this refutes cells around a rotation where
/// several PCs reach the limit of their cones at once while turning apart, once the cells
/// are small against the square root of the slack rather than the slack.

#include "cfgen/verify/analysis.hpp"
#include "cfgen/verify/lp.hpp"

#include <cf/pc.hpp>

#include <vector>

namespace cf::gen {

/// The programs of the first-order test, one per choice of the signs of the set's `e-e`
/// normals (the first `e-e` counting fastest, sign +1 first): variables v (3, each in
/// [-sin theta_max, sin theta_max]), kLessEq rows, in PC order: for each term of the local
/// margin, -beta . v <= alpha + remainder - threshold; for an `e-f` or `f-e`, the two rows of
/// its rotational condition |alpha + beta . v| <= rot_tol + remainder. Empty when the test
/// does not apply: theta_max >= pi / 4 (the first order is worthless), or a PC is an `f-f`.
/// R_c: the cube's central rotation; slack: the local margin each PC must keep (a sine);
/// rot_tol: what a rotational condition may leave at a pose.
std::vector<LinearProgram> first_order_programs(const ModelInfo& a, const ModelInfo& b,
                                                const PcSet& pcs, const Mat3& R_c, double theta_max,
                                                double slack, double rot_tol);

/// The signs (+1 or -1) of the set's e-e normals, in PC order, of program `choice` of
/// first_order_programs: the first e-e counting fastest, +1 first.
std::vector<int> first_order_signs(const PcSet& pcs, std::size_t choice);

/// True when every program of first_order_programs is proven infeasible; its certificates
/// (one per program, in order) go to `proofs` when given. False when the test does not apply
/// or some program is feasible or not proven infeasible.
bool first_order_refutes(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs, const Mat3& R_c,
                         double theta_max, double slack, double rot_tol,
                         std::vector<FarkasCertificate>* proofs = nullptr);

}  // namespace cf::gen
