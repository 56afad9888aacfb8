// transitions_between (tools/cfgen/enumerate/enumerate.cpp) against the definition applied
// to every pair of CFs (docs/generator.md, "Transitions"): gain and lose between a CF and
// one with one PC more; change between CFs of one size whose PCs match one to one, each the
// same PC or a neighbouring one (cf::neighbouring_pcs).
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/execute/executor.hpp"

#include "fixtures.hpp"

#include <cf/pc.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <set>
#include <stdexcept>
#include <tuple>
#include <vector>

namespace {

using Key = std::tuple<int, int, int>;  // from, to, kind

// Whether t matches s one to one, each PC of t the same as or a neighbour of its match.
bool one_change_apart(const cf::PcSet& s, const cf::PcSet& t, const cf::Polyhedron& A,
                      const cf::Polyhedron& B) {
  if (s.size() != t.size() || s == t) return false;
  std::array<int, 3> perm{0, 1, 2};
  do {
    bool all = true;
    for (int k = 0; k < s.size() && all; ++k) {
      const cf::Pc& q = t[perm[static_cast<std::size_t>(k)]];
      const std::vector<cf::Pc> nb = cf::neighbouring_pcs(s[k], A, B);
      all = q == s[k] || std::find(nb.begin(), nb.end(), q) != nb.end();
    }
    if (all) return true;
  } while (std::next_permutation(perm.begin(), perm.begin() + s.size()));
  return false;
}

std::set<Key> by_definition(const std::vector<cf::CfRecord>& cfs, const cf::Polyhedron& A,
                            const cf::Polyhedron& B) {
  std::set<Key> out;
  for (std::size_t i = 0; i < cfs.size(); ++i)
    for (std::size_t j = 0; j < cfs.size(); ++j) {
      const cf::PcSet& s = cfs[i].pcs;
      const cf::PcSet& t = cfs[j].pcs;
      const int a = static_cast<int>(i), b = static_cast<int>(j);
      if (t.size() == s.size() + 1 &&
          std::all_of(s.begin(), s.end(), [&](const cf::Pc& p) { return t.contains(p); })) {
        out.insert({a, b, static_cast<int>(cf::TransitionKind::kGain)});
        out.insert({b, a, static_cast<int>(cf::TransitionKind::kLose)});
      }
      if (one_change_apart(s, t, A, B))
        out.insert({a, b, static_cast<int>(cf::TransitionKind::kChange)});
    }
  return out;
}

}  // namespace

TEST_CASE("transitions: every gain, lose and change the definition gives, and no other",
          "[enumerate]") {
  const cf::Polyhedron A = cf::test::box(10, 20, 30, "A");
  const cf::Polyhedron B = cf::test::small_l_block();
  // A pool of PCs close to each other (a PC, its neighbours and theirs), so that many sets
  // are one change apart; every set of one or two of them, and of three of the first 14.
  std::vector<cf::Pc> pool{{cf::PcType::kFF, 2, 3}};
  for (std::size_t r = 0; r < 2; ++r)
    for (std::size_t i = 0, n = pool.size(); i < n; ++i)
      for (const cf::Pc& q : cf::neighbouring_pcs(pool[i], A, B))
        if (std::find(pool.begin(), pool.end(), q) == pool.end() && pool.size() < 24)
          pool.push_back(q);
  REQUIRE(pool.size() == 24);
  std::vector<cf::CfRecord> cfs;
  auto add = [&](std::vector<cf::Pc> pcs) {
    cf::CfRecord r;
    r.pcs = cf::PcSet(pcs);
    cfs.push_back(r);
  };
  for (std::size_t i = 0; i < pool.size(); ++i) {
    add({pool[i]});
    for (std::size_t j = i + 1; j < pool.size(); ++j) {
      add({pool[i], pool[j]});
      for (std::size_t k = j + 1; k < 14 && j < 14; ++k) add({pool[i], pool[j], pool[k]});
    }
  }
  // Not in PC-set order, as a graph's CFs are not.
  std::reverse(cfs.begin() + 10, cfs.end());
  cf::gen::ExecuteOptions opt;
  opt.threads = 2;
  cf::gen::Executor runner(
      [](const cf::gen::Task&) -> cf::gen::TaskResult {
        throw std::logic_error("no task is decided here");
      },
      opt);
  const std::vector<cf::Transition> got = cf::gen::transitions_between(cfs, A, B, runner);
  std::set<Key> got_keys;
  for (const cf::Transition& t : got)
    got_keys.insert({static_cast<int>(t.from.value()), static_cast<int>(t.to.value()),
                     static_cast<int>(t.kind)});
  CHECK(got_keys.size() == got.size());  // no transition twice
  const std::set<Key> expected = by_definition(cfs, A, B);
  CHECK(expected.size() > 3000);  // the pool is close enough for many changes
  CHECK(got_keys == expected);
  // Sorted by from, to, kind.
  CHECK(
      std::is_sorted(got.begin(), got.end(), [](const cf::Transition& x, const cf::Transition& y) {
        return std::make_tuple(x.from.value(), x.to.value(), static_cast<int>(x.kind)) <
               std::make_tuple(y.from.value(), y.to.value(), static_cast<int>(y.kind));
      }));
}
