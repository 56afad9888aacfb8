#include "finish_contacts.hpp"

#include <cf/pc.hpp>

#include <algorithm>
#include <cmath>

namespace cf::internal {

namespace {

// Sorts the contacts by PC. On packed keys (type, a, b, position) and then one gather: an
// insertion sort moving 160-byte contacts cost half of the finishing on 70 contacts. A few
// contacts (the paper's blocks) sort faster as they are.
constexpr int kFewContacts = 8;
static_assert(ContactSet::kCapacity <= 256, "a contact's position is 8 bits of its sort key");

void sort_contacts(bool small_indices, FinishScratch& s, ContactSet& cs) {
  const int n = cs.size();
  if (!small_indices || n <= kFewContacts) {
    std::sort(cs.begin(), cs.end(),
              [](const ContactPc& x, const ContactPc& y) { return x.pc < y.pc; });
    return;
  }
  for (int i = 0; i < n; ++i) {
    const Pc& p = cs[i].pc;
    s.sort_keys[static_cast<std::size_t>(i)] =
        static_cast<std::uint64_t>(p.type) << 56 | static_cast<std::uint64_t>(p.a) << 32 |
        static_cast<std::uint64_t>(p.b) << 8 | static_cast<std::uint64_t>(i);
  }
  std::sort(s.sort_keys.begin(), s.sort_keys.begin() + n);
  int first_moved = 0;
  while (first_moved < n && (s.sort_keys[static_cast<std::size_t>(first_moved)] & 0xFFu) ==
                                static_cast<std::uint64_t>(first_moved))
    ++first_moved;
  for (int i = first_moved; i < n; ++i)
    s.sort_buf[static_cast<std::size_t>(i)] =
        cs[static_cast<int>(s.sort_keys[static_cast<std::size_t>(i)] & 0xFFu)];
  for (int i = first_moved; i < n; ++i) cs[i] = s.sort_buf[static_cast<std::size_t>(i)];
}

// Where each plane's force acts: the mean of the points of the contacts in its plane, each
// weighted by its fit and by how deep in the band it lies (epsilon - distance, eq. (1)'s
// factor), so that a contact entering the band or leaving its type's conditions moves the
// centre continuously. Over a face flush with the plane its contacts (the f-f, the e-f of
// its edges, the v-f of its corners) weigh alike and the centre is the region's; tilted, it
// runs towards the deeper side. "In its plane" is itself graded, not the groups' yes or no:
// contact j counts for c's plane by how nearly parallel their normals are (1 parallel, 0 at
// the largest angular tolerance) and how nearly their task-frame origins lie in each other's
// planes (1 on them, 0 epsilon off), so that a contact drifting into a plane joins its
// centre continuously.
void plane_centres(double eps, double cos_plane, FinishScratch& s, ContactSet& cs) {
  const int n = cs.size();
  const auto share = [](double x, double scale) {
    return scale > 0 ? std::clamp(x / scale, 0.0, 1.0) : (x >= 0 ? 1.0 : 0.0);
  };
  // Each contact's weight once: the pairs below are n x (contacts that weigh).
  int m = 0;
  for (int j = 0; j < n; ++j) {
    const double w = cs[j].fit * std::max(0.0, eps - cs[j].distance);
    if (w <= 0) continue;
    s.weighted[static_cast<std::size_t>(m)] = j;
    s.weight[static_cast<std::size_t>(m++)] = w;
  }
  for (int i = 0; i < n; ++i) {
    ContactPc& c = cs[i];
    const Vec3 nc = c.R_WT.col(1);
    Vec3 moment = Vec3::Zero();
    double weight = 0;
    for (int k = 0; k < m; ++k) {
      const int j = s.weighted[static_cast<std::size_t>(k)];
      const double w = s.weight[static_cast<std::size_t>(k)];
      const ContactPc& o = cs[j];
      const Vec3 no = o.R_WT.col(1);
      const Vec3 gap = o.origin_W - c.origin_W;
      const double off = std::max(std::abs(nc.dot(gap)), std::abs(no.dot(gap)));
      const double same_plane =
          j == i ? 1.0 : share(nc.dot(no) - cos_plane, 1 - cos_plane) * share(eps - off, eps);
      moment += same_plane * w * o.p_W;
      weight += same_plane * w;
    }
    c.centre_W = weight > 0 ? Vec3(moment / weight) : c.p_W;
  }
}

}  // namespace

void finish_contacts(const FinishContext& ctx, FinishScratch& s, ContactSet& cs) {
  sort_contacts(ctx.small_indices, s, cs);
  const int n = cs.size();
  const double eps = ctx.epsilon_mm;
  // Dominance (docs/spec.md, section 4) by a contact whose shape fits well: its misfit without
  // the distance term (angle / tolerance + in-plane gap / epsilon) is at most dominance_fit. A
  // looser dominator (a face tilted by more than that share of its tolerance over an edge that
  // touches exactly) does not settle the reading: both stand and the previous CF or the fit
  // decides (a hysteresis band instead of a flip at the tolerance). misfit is not changed
  // until every flag is set, so the shapes below are the emitted ones.
  // A dominator's elements hold this one's: of the same or a higher dimension on each
  // side and a higher one on one side at least (two distinct PCs of the same kinds never
  // hold one another). So only f-f, e-f and f-e dominate (below them: v-v, v-e and e-v,
  // which are not PCs), and each type has its possible dominators' types.
  std::array<int, 3> num_dom{};  // f-f, e-f, f-e: PcType's first three
  static_assert(static_cast<int>(PcType::kFF) == 0 && static_cast<int>(PcType::kEF) == 1 &&
                static_cast<int>(PcType::kFE) == 2);
  for (int j = 0; j < n; ++j) {
    const ContactPc& cj = cs[j];
    const auto t = static_cast<std::size_t>(cj.pc.type);
    if (t < 3 && cj.misfit - std::abs(cj.distance) / eps <= ctx.dominance_fit)
      s.dominators[t][static_cast<std::size_t>(num_dom[t]++)] = j;
  }
  const Polyhedron& a = *ctx.a;
  const Polyhedron& b = *ctx.b;
  const auto dominated_by = [&](const ContactPc& ci, PcType type) {
    const auto t = static_cast<std::size_t>(type);
    const ElementKind ai = a_kind(ci.pc.type), bi = b_kind(ci.pc.type), aj = a_kind(type),
                      bj = b_kind(type);
    for (int k = 0; k < num_dom[t]; ++k) {
      const ContactPc& cj = cs[s.dominators[t][static_cast<std::size_t>(k)]];
      if (in_closure(a, ai, ci.pc.a, aj, cj.pc.a) && in_closure(b, bi, ci.pc.b, bj, cj.pc.b))
        return true;
    }
    return false;
  };
  for (ContactPc& ci : cs) {
    if (num_dom[0] + num_dom[1] + num_dom[2] == 0) break;
    switch (ci.pc.type) {
      case PcType::kFF:
        break;
      case PcType::kEF:
      case PcType::kFE:
        ci.dominated = dominated_by(ci, PcType::kFF);
        break;
      case PcType::kVF:
        ci.dominated = dominated_by(ci, PcType::kEF) || dominated_by(ci, PcType::kFF);
        break;
      case PcType::kFV:
        ci.dominated = dominated_by(ci, PcType::kFE) || dominated_by(ci, PcType::kFF);
        break;
      case PcType::kEE:
        ci.dominated = dominated_by(ci, PcType::kEF) || dominated_by(ci, PcType::kFE) ||
                       dominated_by(ci, PcType::kFF);
        break;
    }
  }
  for (ContactPc& c : cs)
    if (c.dominated) c.misfit += ctx.dominance_penalty;
  // Contact planes: greedy clustering in canonical order, each contact against each group's
  // first member.
  int groups = 0;
  for (int i = 0; i < n; ++i) {
    ContactPc& ci = cs[i];
    const Vec3 ni = ci.R_WT.col(1);
    for (int g = 0; g < groups; ++g) {
      const ContactPc& cj = cs[s.reps[static_cast<std::size_t>(g)]];
      const Vec3 nj = cj.R_WT.col(1);
      if (ni.dot(nj) >= ctx.cos_plane_tolerance &&
          std::abs(nj.dot(ci.origin_W - cj.origin_W)) <= eps &&
          std::abs(ni.dot(cj.origin_W - ci.origin_W)) <= eps) {
        ci.plane = static_cast<std::int16_t>(g);
        break;
      }
    }
    if (ci.plane < 0) {
      s.reps[static_cast<std::size_t>(groups)] = i;
      ci.plane = static_cast<std::int16_t>(groups++);
    }
  }
  cs.set_num_planes(groups);
  plane_centres(eps, ctx.cos_plane_tolerance, s, cs);
}

}  // namespace cf::internal
