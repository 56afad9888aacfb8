#include "recall.hpp"

#include "shapes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

namespace oracle {

namespace fs = std::filesystem;

std::string signature(const CfKey& k) {
  std::string s = std::to_string(k.size()) + ":";
  for (std::size_t i = 0; i < k.size(); ++i)
    s += (i ? "+" : "") + std::string(type_name(k[i].type));
  return s;
}

std::string pose_arg(const Pose& X) {
  std::string s;
  char b[40];
  for (int i = 0; i < 9; ++i) {
    std::snprintf(b, sizeof b, "%s%.17g", i ? "," : "", X.R(i / 3, i % 3));
    s += b;
  }
  for (int i = 0; i < 3; ++i) {
    std::snprintf(b, sizeof b, ",%.17g", X.t(i));
    s += b;
  }
  return s;
}

bool parse_pose_arg(const std::string& a, Pose* X) {
  std::vector<double> v;
  std::size_t i = 0;
  while (i <= a.size()) {
    std::size_t j = a.find(',', i);
    if (j == std::string::npos) j = a.size();
    try {
      std::size_t used = 0;
      std::string tok = a.substr(i, j - i);
      v.push_back(std::stod(tok, &used));
      if (used != tok.size()) return false;
    } catch (...) {
      return false;
    }
    i = j + 1;
  }
  if (v.size() != 12) return false;
  for (double x : v)
    if (!std::isfinite(x)) return false;
  for (int k = 0; k < 9; ++k) X->R(k / 3, k % 3) = v[k];
  X->t = Vec3(v[9], v[10], v[11]);
  return (X->R.transpose() * X->R - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-6 &&
         X->R.determinant() > 0;
}

std::string RecallResult::line() const {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s graph=%d sampled=%d misses=%zu thin=%zu recall=%.1f%% unsound=%d marginal=%d "
                "dropped=%d "
                "cfgen=%.1fs "
                "sampler=%.1fs",
                from_seed ? ((extra >= 0 ? "extra=" + std::to_string(extra) + " " : std::string()) +
                             "seed=" + std::to_string(seed))
                                .c_str()
                          : "files",
                graph_cfs, sampled, misses.size(), thin.size(), recall(), check.unsound,
                check.marginal, unstable + suspect, cfgen_s, sampler_s);
  std::string s = buf;
  if (!ok) s += " ERROR: " + error;
  if (!model_problems.empty()) s += " MODEL-MISMATCH";
  return s + " | " + desc;
}

std::string RecallResult::details() const {
  std::ostringstream o;
  const std::string seed_arg =
      (extra >= 0 ? "--extra " + std::to_string(extra) + " " : std::string()) + "--seed " +
      std::to_string(seed);
  std::string who = !from_seed ? a_path + " " + b_path
                    : extra >= 0
                        ? "extra " + std::to_string(extra) + " seed " + std::to_string(seed)
                        : "seed " + std::to_string(seed);
  for (const auto& p : model_problems) o << "  MODEL " << who << ": " << p << "\n";
  for (const auto& p : pose_reports) o << "  CHECK " << p << "\n";
  if (ok) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "  witnesses: %d checked in %.1f s, %d sound (smallest clearance %.4g mm), %d "
                  "marginal, %d unsound\n",
                  check.total, check_s, check.sound, check.min_clearance, check.marginal,
                  check.unsound);
    o << buf;
  }
  int n = 0;
  for (const auto& w : check.bad) {
    if (n++ >= 20) {
      o << "  ... " << check.bad.size() - 20 << " more bad witnesses\n";
      break;
    }
    o << "  " << (w.verdict == 2 ? "UNSOUND" : "MARGINAL") << " witness " << who << " cf " << w.id
      << " {" << key_string(w.key) << "}: " << w.problem << "\n    pose " << pose_string(w.pose)
      << "\n";
    if (from_seed)
      o << "    recheck: oracle_recall " << seed_arg << " --budget 0 --pose " << pose_arg(w.pose)
        << "\n";
  }
  for (const auto& m : suspects)
    o << "  SUSPECT (not counted: the Monte-Carlo check found points of A inside B) " << who << " {"
      << key_string(m.key) << "}\n    pose " << pose_string(m.sample.pose) << "\n";
  for (const auto& m : thin) {
    char cl[64];
    std::snprintf(cl, sizeof cl, "%.4g", m.sample.clearance);
    o << "  THIN (listed in the graph's stats.thin_sets, not a miss) " << who << " {"
      << key_string(m.key) << "} clearance " << cl << " mm\n";
  }
  std::map<std::string, int> groups;
  for (const auto& m : misses) groups[signature(m.key)]++;
  if (!misses.empty()) {
    o << "  misses by signature:";
    for (const auto& [s, c] : groups) o << " " << s << " x" << c;
    int low = 0;
    for (const auto& m : misses) low += m.sample.clearance < 0.01 ? 1 : 0;
    o << "\n  misses whose best oracle pose has clearance below 0.01 mm: " << low << "\n";
  }
  n = 0;
  for (const auto& m : misses) {
    if (n++ >= 30) {
      o << "  ... " << misses.size() - 30 << " more misses\n";
      break;
    }
    char cl[64];
    std::snprintf(cl, sizeof cl, "%.4g", m.sample.clearance);
    o << "  MISS " << who << " {" << key_string(m.key) << "} clearance " << cl << " mm"
      << (m.sample.clearance < 0.01 ? " (below cfgen's default --min-clearance 0.01 mm)" : "")
      << " via " << m.sample.how << "\n    pose " << pose_string(m.sample.pose) << "\n";
    if (from_seed)
      o << "    recheck: oracle_recall " << seed_arg << " --budget 0 --pose "
        << pose_arg(m.sample.pose) << "\n";
  }
  return o.str();
}

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

int run_program(const std::vector<std::string>& args, const std::string& log, double timeout_s) {
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& x : copy) argv.push_back(x.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
      close(fd);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  int st = 0;
  if (timeout_s > 0) {
    const double t0 = now_s();
    for (;;) {
      const pid_t w = waitpid(pid, &st, WNOHANG);
      if (w == pid) break;
      if (w < 0) return -1;
      if (now_s() - t0 > timeout_s) {
        kill(pid, SIGKILL);
        waitpid(pid, &st, 0);
        return -2;
      }
      usleep(50000);
    }
  } else if (waitpid(pid, &st, 0) < 0) {
    return -1;
  }
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

namespace {

std::string fmt17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// Runs cfgen, writing the graph g and its certificate file c; returns its exit status (-1
// when it could not start); output to log.
int run_cfgen(const std::string& cfgen, const std::string& a, const std::string& b,
              const std::string& g, const std::string& c, int threads, const std::string& log,
              double timeout_s) {
  return run_program(
      {cfgen, a, b, "-o", g, "--certificates", c, "-q", "-j", std::to_string(threads)}, log,
      timeout_s);
}

std::string slurp(const std::string& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void compare_model(const Mesh& m, const Poly& P, const char* which, std::vector<std::string>* out) {
  double vm = mesh_volume(m), vp = P.volume();
  double am = mesh_area(m), ap = P.surface_area();
  char buf[256];
  if (std::abs(vm - vp) > 1e-6 * std::abs(vm)) {
    std::snprintf(buf, sizeof buf,
                  "%s: volume of the graph model %.9g differs from the mesh's %.9g", which, vp, vm);
    out->push_back(buf);
  }
  if (std::abs(am - ap) > 1e-6 * am) {
    std::snprintf(buf, sizeof buf,
                  "%s: surface area of the graph model %.9g differs from the mesh's %.9g", which,
                  ap, am);
    out->push_back(buf);
  }
  int nf = count_planar_faces(m);
  if (nf != static_cast<int>(P.F.size())) {
    std::snprintf(buf, sizeof buf,
                  "%s: the graph model has %zu faces, the mesh %d maximal planar regions", which,
                  P.F.size(), nf);
    out->push_back(buf);
  }
  int nv = count_corner_vertices(m);
  if (nv != static_cast<int>(P.V.size())) {
    std::snprintf(buf, sizeof buf,
                  "%s: the graph model has %zu vertices, the mesh %d corners of 3+ faces", which,
                  P.V.size(), nv);
    out->push_back(buf);
  }
}

// Points of A (random in A, and near each contact) that lie inside B farther than 10 tol from
// B's boundary.
int mc_points_inside(const Poly& A, const Poly& B, const Pose& X, const Verdict& V, double tol,
                     std::uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x5bd1e995ULL);
  std::uniform_real_distribution<double> u01(0, 1);
  std::normal_distribution<double> N(0, 1);
  auto far_inside_b = [&](const Vec3& w) {
    if (!point_in_solid(B, w)) return false;
    for (const Face& f : B.F)
      if (point_face_dist(B, f, w) <= 10 * tol) return false;
    return true;
  };
  int bad = 0, tried = 0;
  const Vec3 lo = A.box.lo, ext = A.box.hi - A.box.lo;
  for (int i = 0; i < 20000 && tried < 3000; ++i) {
    Vec3 p = lo + Vec3(u01(rng) * ext.x(), u01(rng) * ext.y(), u01(rng) * ext.z());
    if (!point_in_solid(A, p)) continue;
    ++tried;
    if (far_inside_b(X.apply(p))) ++bad;
  }
  for (int i : V.pcs) {
    Vec3 c = X.inv(V.touches[i].p0);
    for (int k = 0; k < 400; ++k) {
      double r = A.diag * std::pow(10.0, -1 - 3 * u01(rng));
      Vec3 p = c + r * Vec3(N(rng), N(rng), N(rng)).normalized();
      if (!point_in_solid(A, p)) continue;
      if (far_inside_b(X.apply(p))) ++bad;
    }
  }
  return bad;
}

RecallResult run_pair(const Mesh& A, const Mesh& B, const std::string& dir, const RecallOptions& o,
                      RecallResult r, bool write_models) {
  r.a_path = (fs::path(dir) / "A.off").string();
  r.b_path = (fs::path(dir) / "B.off").string();
  r.graph_path = (fs::path(dir) / "G.json").string();
  r.cert_path = (fs::path(dir) / "C.json").string();
  try {
    if (write_models) {
      write_off(A, r.a_path);
      write_off(B, r.b_path);
    }
    double t0 = now_s();
    std::string log = (fs::path(dir) / "cfgen.log").string();
    int rc = run_cfgen(o.cfgen, r.a_path, r.b_path, r.graph_path, r.cert_path, o.threads, log,
                       o.cfgen_timeout_s);
    r.cfgen_s = now_s() - t0;
    if (rc == -2) {
      r.error = "cfgen did not finish within " +
                std::to_string(static_cast<int>(o.cfgen_timeout_s)) + " s";
      return r;
    }
    if (rc != 0) {
      std::string l = slurp(log);
      while (!l.empty() && (l.back() == '\n' || l.back() == '\r')) l.pop_back();
      r.error = "cfgen exited with status " + std::to_string(rc) + ": " + l;
      return r;
    }
    Graph G = read_graph(r.graph_path);
    r.graph_cfs = static_cast<int>(G.cfs.size());
    compare_model(A, G.A, "A", &r.model_problems);
    compare_model(B, G.B, "B", &r.model_problems);
    Tolerances tol = default_tolerances(G.A, G.B);
    double t1 = now_s();
    r.check = check_graph(G, tol);
    r.check_s = now_s() - t1;
    Classifier C(G.A, G.B, tol);
    std::set<CfKey> in_graph;
    for (const auto& cf : G.cfs) in_graph.insert(cf.key);
    for (const Pose& X : o.check_poses) {
      Verdict v = C.classify(X, true);
      std::string rep = "pose " + pose_string(X) + "\n    oracle: " + v.describe();
      if (v.valid_cf() && v.uncertain.empty())
        rep += in_graph.count(v.key()) ? "\n    the graph holds this CF"
                                       : "\n    the graph does NOT hold this CF";
      r.pose_reports.push_back(rep);
    }
    SamplerOptions so;
    so.budget_s = o.budget_s;
    so.max_rounds = o.sampler_rounds;
    so.seed = o.sampler_seed ? o.sampler_seed : (r.seed * 0x9E3779B97F4A7C15ULL + 12345);
    Sampler S(C, so);
    S.run();
    r.sampler_s = S.stats().seconds;
    r.sampler_stats = S.stats();
    // Second opinions before anything counts: the same classification at tol/10 and tol*10
    // (a CF whose PCs change within that range is dropped), and for misses a Monte-Carlo
    // search for points of A inside B (a safety net under the exact test).
    // With a kept directory: samples.csv, the CFs the oracle realised that the graph holds.
    std::unique_ptr<std::ofstream> samples_out;
    if (!o.keep_dir.empty()) {
      samples_out = std::make_unique<std::ofstream>(fs::path(dir) / "samples.csv");
      *samples_out << "pcs,free_clearance_mm,R00,R01,R02,R10,R11,R12,R20,R21,R22,tx,ty,tz\n";
    }
    Tolerances tlo = tol, thi = tol;
    tlo.len /= 10;
    thi.len *= 10;
    Classifier Clo(G.A, G.B, tlo), Chi(G.A, G.B, thi);
    const std::set<CfKey> thin(G.thin.begin(), G.thin.end());
    for (const auto& [k, s] : S.samples()) {
      Verdict a = Clo.classify(s.pose, false), b = Chi.classify(s.pose, false);
      if (!a.valid_cf() || !b.valid_cf() || a.key() != k || b.key() != k) {
        ++r.unstable;
        continue;
      }
      ++r.sampled;
      if (in_graph.count(k)) {
        ++r.found;
        if (samples_out) {
          // The CF's pose for the run time's identification test
          // (tests/libcf/identify_oracle_test): its PCs, how far the nearest contact that is
          // not another reading of them is, and the pose.
          const double free_mm = C.clearance_outside(s.pose, k);
          *samples_out << key_string(k) << ',' << (std::isfinite(free_mm) ? free_mm : 1e9);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) *samples_out << ',' << fmt17(s.pose.R(i, j));
          for (int i = 0; i < 3; ++i) *samples_out << ',' << fmt17(s.pose.t(i));
          *samples_out << '\n';
        }
        continue;
      }
      Verdict v = C.classify(s.pose, false);
      if (mc_points_inside(G.A, G.B, s.pose, v, tol.len, so.seed) > 0) {
        ++r.suspect;
        r.suspects.push_back(Miss{k, s});
        continue;
      }
      if (s.clearance < G.min_clearance_mm && thin.count(k))
        r.thin.push_back(Miss{k, s});
      else
        r.misses.push_back(Miss{k, s});
    }
    r.ok = true;
    if (o.inspect) o.inspect(r);  // while the files are there
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  return r;
}

std::string make_dir(const RecallOptions& o, const std::string& leaf, bool* temporary) {
  if (!o.keep_dir.empty()) {
    fs::path d = fs::path(o.keep_dir) / leaf;
    fs::create_directories(d);
    *temporary = false;
    return d.string();
  }
  std::string tmpl = (fs::temp_directory_path() / "oracle_recall_XXXXXX").string();
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (!mkdtemp(buf.data())) throw std::runtime_error("cannot create a temporary directory");
  *temporary = true;
  return std::string(buf.data());
}

RecallResult run_generated(const ShapePair& P, RecallResult r, const std::string& leaf,
                           const RecallOptions& o) {
  r.from_seed = true;
  r.desc = P.desc;
  std::string pa = check_mesh(P.A), pb = check_mesh(P.B);
  if (!pa.empty() || !pb.empty()) {
    r.error = "generated mesh broken: A: " + pa + " B: " + pb;
    return r;
  }
  bool tmp = false;
  std::string dir;
  try {
    dir = make_dir(o, leaf, &tmp);
  } catch (const std::exception& e) {
    r.error = e.what();
    return r;
  }
  r = run_pair(P.A, P.B, dir, o, r, true);
  if (tmp) {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  return r;
}

}  // namespace

RecallResult run_recall_seed(std::uint64_t seed, const RecallOptions& o) {
  RecallResult r;
  r.seed = seed;
  return run_generated(make_pair(seed), r, "seed_" + std::to_string(seed), o);
}

RecallResult run_recall_extra(int which, std::uint64_t seed, const RecallOptions& o) {
  RecallResult r;
  r.seed = seed;
  r.extra = which;
  return run_generated(make_extra_pair(which, seed), r,
                       "extra_" + std::to_string(which) + "_seed_" + std::to_string(seed), o);
}

RecallResult run_recall_files(const std::string& a_off, const std::string& b_off,
                              const RecallOptions& o) {
  RecallResult r;
  r.desc = a_off + " | " + b_off;
  bool tmp = false;
  std::string dir;
  try {
    Mesh A = read_off(a_off), B = read_off(b_off);
    dir = make_dir(o, "files", &tmp);
    // cfgen reads the given files; copies go to dir so that everything is in one place
    fs::copy_file(a_off, fs::path(dir) / "A.off", fs::copy_options::overwrite_existing);
    fs::copy_file(b_off, fs::path(dir) / "B.off", fs::copy_options::overwrite_existing);
    r = run_pair(A, B, dir, o, r, false);
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  if (tmp) {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  return r;
}

}  // namespace oracle
