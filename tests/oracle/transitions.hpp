#pragma once
// Independent test oracle: which CFs are one transition apart (docs/spec.md, section 4,
// "Neighbouring PCs and transitions"), from the PC lists and the elements' adjacency alone.
// A gain adds one PC; a change keeps the number of PCs and replaces some of them by
// neighbouring PCs, two PCs being neighbours when one turns into the other through one
// degenerate touch under the matching boundary relation (the edge bounds the face, the vertex
// ends the edge).

#include "classify.hpp"

namespace oracle {

/// True when PCs `x` and `y` are neighbours, in either order: f-f with e-f (same B face, the
/// edge bounds A's face) or with f-e (same A face, the edge bounds B's face); e-f with v-f (same
/// B face, the vertex ends A's edge) or with e-e (same A edge, B's edge bounds the face); f-e
/// with f-v (same A face, the vertex ends B's edge) or with e-e (same B edge, A's edge bounds
/// the face); v-f with e-e (A's vertex ends A's edge, B's edge bounds B's face) and f-v with e-e
/// likewise. A PC is not its own neighbour.
bool neighbouring_pcs(const Poly& A, const Poly& B, const Pc& x, const Pc& y);

/// True when `to` is `from` with exactly one PC added (a gain from -> to; its reverse, a lose
/// of one PC). Both sorted, as CfKey is.
bool is_gain(const CfKey& from, const CfKey& to);

/// True when `from` -> `to` is a change: the same number of PCs, different sets, and some
/// one-to-one pairing maps each PC of `from` to an equal or a neighbouring PC of `to`.
bool is_change(const Poly& A, const Poly& B, const CfKey& from, const CfKey& to);

}  // namespace oracle
