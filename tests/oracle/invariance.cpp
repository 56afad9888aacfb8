#include "invariance.hpp"
#include "recall.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

namespace oracle {

namespace fs = std::filesystem;

Mesh moved_renumbered(const Mesh& m, const Pose& X, std::mt19937_64& rng) {
  std::vector<int> order(m.V.size());  // new vertex k is old vertex order[k]
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<int> new_index(m.V.size());
  for (std::size_t k = 0; k < order.size(); ++k) new_index[order[k]] = static_cast<int>(k);
  Mesh out;
  out.name = m.name + " (moved, renumbered)";
  for (int old : order) out.V.push_back(X.apply(m.V[old]));
  for (const auto& f : m.F) {
    std::vector<int> g;
    for (int v : f) g.push_back(new_index[v]);
    const auto start = std::uniform_int_distribution<std::size_t>(0, g.size() - 1)(rng);
    std::rotate(g.begin(), g.begin() + static_cast<std::ptrdiff_t>(start), g.end());
    out.F.push_back(g);
  }
  std::shuffle(out.F.begin(), out.F.end(), rng);
  return out;
}

ElementMap map_elements(const Poly& moved, const Poly& first, const Pose& X, double rel_tol) {
  ElementMap m;
  const double tol = rel_tol * first.diag;
  for (std::size_t i = 0; i < moved.V.size(); ++i) {
    const Vec3 p = X.inv(moved.V[i].p);
    int best = -1;
    double best_d = tol;
    for (std::size_t j = 0; j < first.V.size(); ++j) {
      const double d = (first.V[j].p - p).norm();
      if (d <= best_d) best = static_cast<int>(j), best_d = d;
    }
    if (best < 0) {
      m.problem = "vertex " + std::to_string(i) + " of the moved model has no vertex of the first";
      return m;
    }
    m.vertex.push_back(best);
  }
  for (std::size_t i = 0; i < moved.E.size(); ++i) {
    const int e = first.edge_index(m.vertex[moved.E[i].v0], m.vertex[moved.E[i].v1]);
    if (e < 0) {
      m.problem = "edge " + std::to_string(i) + " of the moved model has no edge of the first";
      return m;
    }
    m.edge.push_back(e);
  }
  // Faces by their vertex sets, the first model's indexed once.
  std::map<std::set<int>, int> first_faces;
  for (std::size_t j = 0; j < first.F.size(); ++j)
    first_faces.emplace(std::set<int>(first.F[j].verts.begin(), first.F[j].verts.end()),
                        static_cast<int>(j));
  for (std::size_t i = 0; i < moved.F.size(); ++i) {
    std::set<int> s;
    for (int v : moved.F[i].verts) s.insert(m.vertex[static_cast<std::size_t>(v)]);
    const auto it = first_faces.find(s);
    if (it == first_faces.end()) {
      m.problem = "face " + std::to_string(i) + " of the moved model has no face of the first";
      return m;
    }
    m.face.push_back(it->second);
  }
  return m;
}

CfKey map_key(const CfKey& key, const ElementMap& a, const ElementMap& b) {
  // Element kinds of each side of a PC type (f-f, e-f, f-e, v-f, f-v, e-e).
  auto side = [](const ElementMap& m, char kind, int i) {
    return kind == 'v' ? m.vertex[i] : kind == 'e' ? m.edge[i] : m.face[i];
  };
  CfKey out;
  for (const Pc& pc : key) {
    const std::string t = type_name(pc.type);
    out.push_back(Pc{pc.type, side(a, t[0], pc.a), side(b, t[2], pc.b)});
  }
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

// Runs cfgen on a and b writing g, its output to log; returns the exit status (-1: no start).
int run(const InvarianceOptions& o, const std::string& a, const std::string& b,
        const std::string& g, const std::string& log) {
  std::vector<std::string> args{o.cfgen, a, b, "-o", g, "-q", "-j", std::to_string(o.threads)};
  args.insert(args.end(), o.cfgen_args.begin(), o.cfgen_args.end());
  return run_program(args, log);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<CfKey> difference(const std::set<CfKey>& x, const std::set<CfKey>& y) {
  std::vector<CfKey> out;
  std::set_difference(x.begin(), x.end(), y.begin(), y.end(), std::back_inserter(out));
  return out;
}

// How many CFs of g whose keys, mapped by `key_of`, are in `only` have a witness the oracle
// finds sound.
template <typename KeyOf>
int count_sound(const Graph& g, const std::vector<CfKey>& only, KeyOf key_of) {
  const std::set<CfKey> wanted(only.begin(), only.end());
  return check_graph(g, default_tolerances(g.A, g.B),
                     [&](const GraphCf& cf) { return wanted.count(key_of(cf.key)) > 0; })
      .sound;
}

// The inverse of a map from the moved graph's elements to the first's.
ElementMap inverse(const ElementMap& m) {
  ElementMap inv;
  auto flip = [](const std::vector<int>& v) {
    std::vector<int> w(v.size(), -1);
    for (std::size_t i = 0; i < v.size(); ++i) w[static_cast<std::size_t>(v[i])] = int(i);
    return w;
  };
  inv.vertex = flip(m.vertex);
  inv.edge = flip(m.edge);
  inv.face = flip(m.face);
  return inv;
}

// One line per set only one graph holds: "first"/"moved", the set in the first graph's
// numbering, and its witness in the first files' frames (R row by row, then t); then after
// "| moved:" the set in the moved graph's numbering and the witness in the moved files'
// frames, so that a missed CF can be examined against the run that missed it.
void write_differences(const std::string& path, const Graph& first, const Graph& moved,
                       const InvarianceResult& r, const ElementMap& ma, const ElementMap& mb,
                       const Pose& XA, const Pose& XB) {
  std::ofstream out(path);
  out.precision(17);
  const ElementMap ia = inverse(ma), ib = inverse(mb);
  auto pose = [&](const Pose& X) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out << " " << X.R(i, j);
    for (int i = 0; i < 3; ++i) out << " " << X.t(i);
  };
  auto line = [&](const char* which, const CfKey& key, const Pose& X) {
    out << which << " " << key_string(key) << " |";
    pose(X);
    // In the moved frames: x'_B = XB(X(XA^-1(x'_A))).
    Pose Y;
    Y.R = XB.R * X.R * XA.R.transpose();
    Y.t = XB.R * (X.t - X.R * XA.R.transpose() * XA.t) + XB.t;
    out << " | moved: " << key_string(map_key(key, ia, ib)) << " |";
    pose(Y);
    out << "\n";
  };
  const std::set<CfKey> only_first(r.only_first.begin(), r.only_first.end());
  const std::set<CfKey> only_moved(r.only_moved.begin(), r.only_moved.end());
  for (const GraphCf& cf : first.cfs)
    if (only_first.count(cf.key)) line("first", cf.key, cf.witness);
  for (const GraphCf& cf : moved.cfs) {
    const CfKey key = map_key(cf.key, ma, mb);
    if (!only_moved.count(key)) continue;
    // A's point x sits at XB.inv(Xw(XA(x))) in the first files' frame of B.
    Pose X;
    X.R = XB.R.transpose() * cf.witness.R * XA.R;
    X.t = XB.R.transpose() * (cf.witness.R * XA.t + cf.witness.t - XB.t);
    line("moved", key, X);
  }
}

}  // namespace

InvarianceResult run_invariance(const ShapePair& pair, const InvarianceOptions& o) {
  InvarianceResult r;
  r.desc = pair.desc;
  const bool temporary = o.keep_dir.empty();
  const fs::path dir =
      temporary ? fs::temp_directory_path() / ("oracle_invariance_" + std::to_string(::getpid()))
                : fs::path(o.keep_dir);
  fs::create_directories(dir);
  std::mt19937_64 rng(o.motion_seed);
  const Pose XA = random_rigid(rng), XB = random_rigid(rng);
  write_off(pair.A, (dir / "A.off").string());
  write_off(pair.B, (dir / "B.off").string());
  const std::string moved_ext = o.float32_stl ? ".stl" : ".off";
  const auto write = o.float32_stl ? write_stl_float32 : write_off;
  write(moved_renumbered(pair.A, XA, rng), (dir / ("A_moved" + moved_ext)).string());
  write(moved_renumbered(pair.B, XB, rng), (dir / ("B_moved" + moved_ext)).string());
  try {
    auto generate = [&](const std::string& suffix, double& seconds) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::string g = (dir / ("G" + suffix + ".json")).string();
      const std::string ext = suffix.empty() ? ".off" : moved_ext;
      const int rc =
          run(o, (dir / ("A" + suffix + ext)).string(), (dir / ("B" + suffix + ext)).string(), g,
              (dir / ("cfgen" + suffix + ".log")).string());
      seconds = seconds_since(t0);
      if (rc != 0)
        throw std::runtime_error("cfgen exited with status " + std::to_string(rc) + " (see " +
                                 (dir / ("cfgen" + suffix + ".log")).string() + ")");
      return read_graph(g);
    };
    const Graph first = generate("", r.first_s), moved = generate("_moved", r.moved_s);
    // float32 holds a coordinate to 6e-8 of it; the models sit within a few diagonals of
    // their origins.
    const double map_tol = o.float32_stl ? 1e-5 : 1e-7;
    const ElementMap ma = map_elements(moved.A, first.A, XA, map_tol);
    const ElementMap mb = map_elements(moved.B, first.B, XB, map_tol);
    if (!ma.problem.empty() || !mb.problem.empty())
      throw std::runtime_error("the graphs' models differ: A: " + ma.problem +
                               "; B: " + mb.problem);
    std::set<CfKey> a, b;
    for (const GraphCf& cf : first.cfs) a.insert(cf.key);
    for (const GraphCf& cf : moved.cfs) b.insert(map_key(cf.key, ma, mb));
    r.first_cfs = static_cast<int>(first.cfs.size());
    r.moved_cfs = static_cast<int>(moved.cfs.size());
    r.only_first = difference(a, b);
    r.only_moved = difference(b, a);
    r.sound_first = count_sound(first, r.only_first, [](const CfKey& k) { return k; });
    r.sound_moved =
        count_sound(moved, r.only_moved, [&](const CfKey& k) { return map_key(k, ma, mb); });
    if (!temporary)
      write_differences((dir / "differences.txt").string(), first, moved, r, ma, mb, XA, XB);
    r.ok = true;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  if (temporary && r.ok) {  // a failed run's files stay, for its log
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  return r;
}

}  // namespace oracle
