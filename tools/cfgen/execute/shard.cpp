#include "cfgen/execute/shard.hpp"

#include <cf/file_io.hpp>
#include <cf/types.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>

namespace cf::tools {
namespace {

// The version of checkpoints and of the fingerprint. 2: a witness as in chunks, [found, pose
// (12), clearance, margin]; 3: the witness search climbs past obstacles and the neighbour
// rounds' tasks (the same tasks give other results, so checkpoints of version 2 are refused);
// 4: the images of each batch of CFs found verified as a stage of kVerify tasks (the stages
// are numbered differently); 5: the neighbour rounds' screening in stages of its own; 6: an
// image that does not verify at the image of its witness is polished (kVerify tasks give
// other results) and symmetries hold to the files' rounding.
constexpr int kVersion = 6;
constexpr int kMaxShards = 4096;

// The options that shape the graph, in a fixed order (not the thread count, the output or
// --quiet, which do not change a byte of it).
nlohmann::json options_json(const GenerateArgs& a) {
  nlohmann::json o = {{"max_pcs", a.max_pcs},
                      {"symmetry", a.symmetry},
                      {"touch_tol_rel", a.rel.touch_tol},
                      {"min_clearance_rel", a.rel.min_clearance},
                      {"good_clearance_rel", a.rel.good_clearance},
                      {"min_margin_rel", a.rel.min_margin},
                      {"angle_margin_rad", a.search.angle_margin},
                      {"theta_samples", a.search.theta_samples},
                      {"max_rotations", a.search.max_rotations},
                      {"max_piece_combinations", a.search.max_piece_combinations},
                      {"units_a", a.load_a.units},
                      {"units_b", a.load_b.units},
                      {"coplanar_tol_a", a.load_a.coplanar_rel_tol},
                      {"coplanar_tol_b", a.load_b.coplanar_rel_tol},
                      {"crease_angle_a", a.load_a.crease_angle_deg},
                      {"crease_angle_b", a.load_b.crease_angle_deg}};
  // Only when set, so that the fingerprints of runs without it are those of earlier builds.
  if (a.thorough) o["thorough"] = true;
  return o;
}

// The JSON document in file `path`; errors read "<what> '<path>': <reason><hint>".
nlohmann::json read_json_file(const std::string& path, const std::string& what,
                              const std::string& hint = "") {
  std::string bytes, why;
  if (!read_input_file(path, bytes, why)) throw Error(what + " '" + path + "': " + why);
  try {
    return nlohmann::json::parse(bytes);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(what + " '" + path + "': not JSON (" + e.what() + ")" + hint);
  }
}

std::uint64_t fnv1a(std::uint64_t h, const std::string& bytes) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  // Length too, so that concatenations cannot collide by shifting bytes between fields.
  const std::string len = std::to_string(bytes.size()) + ";";
  for (unsigned char c : len) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

// A pose as 12 numbers (R row by row, then t) and back: doubles round-trip exactly.
nlohmann::json pose_json(const Pose& p) {
  nlohmann::json out = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.push_back(p.R_BA(r, c));
  for (int r = 0; r < 3; ++r) out.push_back(p.t_BA(r));
  return out;
}

nlohmann::json pcs_json(const PcSet& s) {
  nlohmann::json out = nlohmann::json::array();
  for (const Pc& pc : s) out.push_back({static_cast<int>(pc.type), pc.a, pc.b});
  return out;
}

// Reads what the functions above write; `bad` throws with the problem.
struct Reader {
  std::function<void(const std::string&)> bad;
  Pose pose(const nlohmann::json& j) const {
    if (!j.is_array() || j.size() != 12) bad("expected a pose of 12 numbers");
    Pose p;
    for (int k = 0; k < 12; ++k) {
      if (!j[k].is_number()) bad("a pose holds a non-number");
      const double v = j[k].get<double>();
      if (k < 9)
        p.R_BA(k / 3, k % 3) = v;
      else
        p.t_BA(k - 9) = v;
    }
    return p;
  }
  PcSet pcs(const nlohmann::json& j) const {
    if (!j.is_array() || j.empty() || j.size() > PcSet::kMaxPcs)
      bad("expected a set of 1 to 3 PCs");
    PcSet s;
    for (const nlohmann::json& pc : j) {
      if (!pc.is_array() || pc.size() != 3 || !pc[0].is_number_unsigned() ||
          !pc[1].is_number_unsigned() || !pc[2].is_number_unsigned() ||
          pc[0].get<unsigned>() > static_cast<unsigned>(PcType::kEE))
        bad("expected a PC [type, a, b]");
      if (!s.insert(Pc{static_cast<PcType>(pc[0].get<int>()), pc[1].get<int>(), pc[2].get<int>()}))
        bad("a PC is repeated");
    }
    return s;
  }
  // What sets_text writes: "t.a.b,t.a.b t.a.b" (PCs by ',', sets by ' ').
  std::vector<PcSet> sets(const std::string& text) const {
    const char* p = text.c_str();
    auto form = [&] { bad("expected sets as \"t.a.b,t.a.b t.a.b\""); };
    auto number = [&](long long most) {
      long long v = 0;
      if (*p < '0' || *p > '9') form();
      for (; *p >= '0' && *p <= '9'; ++p)
        if ((v = 10 * v + (*p - '0')) > most) form();
      return static_cast<int>(v);
    };
    std::vector<PcSet> out;
    while (*p) {
      PcSet set;
      for (;;) {
        const int t = number(static_cast<int>(PcType::kEE));
        if (*p++ != '.') form();
        const int a = number(std::numeric_limits<int>::max());
        if (*p++ != '.') form();
        const int b = number(std::numeric_limits<int>::max());
        if (set.size() == PcSet::kMaxPcs) form();
        if (!set.insert(Pc{static_cast<PcType>(t), a, b})) bad("a PC is repeated");
        if (*p != ',') break;
        ++p;
      }
      out.push_back(set);
      if (*p == ' ' && p[1])
        ++p;
      else if (*p)
        form();
    }
    return out;
  }
  gen::Witness witness(const nlohmann::json& j) const {
    gen::Witness w;
    if (!j.is_array() || j.empty() || !j[0].is_boolean()) bad("expected a witness [found, ...]");
    w.found = j[0].get<bool>();
    if (!w.found) return w;
    if (j.size() != 4 || !j[2].is_number() || !j[3].is_number())
      bad("expected [true, pose, clearance, margin]");
    w.pose = pose(j[1]);
    w.clearance = j[2].get<double>();
    w.margin = j[3].get<double>();
    return w;
  }
};

nlohmann::json witness_json(const gen::Witness& w) {
  if (!w.found) return nlohmann::json::array({false});
  return {true, pose_json(w.pose), w.clearance, w.margin};
}

// Sets as one string: a chunk of screening holds thousands, and a JSON value each would cost
// more than the screening.
std::string sets_text(const std::vector<PcSet>& sets) {
  std::string out;
  char buf[48];
  for (const PcSet& s : sets) {
    if (!out.empty()) out += ' ';
    for (int k = 0; k < s.size(); ++k) {
      std::snprintf(buf, sizeof buf, "%s%d.%d.%d", k ? "," : "", static_cast<int>(s[k].type),
                    s[k].a, s[k].b);
      out += buf;
    }
  }
  return out;
}

nlohmann::json task_results_json(const std::vector<gen::TaskResult>& results) {
  nlohmann::json out = nlohmann::json::array();
  for (const gen::TaskResult& r : results) {
    nlohmann::json met = nlohmann::json::array();
    for (const gen::Discovery& d : r.met) met.push_back({pcs_json(d.pcs), pose_json(d.pose)});
    nlohmann::json one = {witness_json(r.witness), met};
    if (!r.sets.empty()) one.push_back(sets_text(r.sets));
    out.push_back(std::move(one));
  }
  return out;
}

std::vector<gen::TaskResult> parse_task_results(const nlohmann::json& j, const Reader& rd) {
  if (!j.is_array()) rd.bad("expected an array of results");
  std::vector<gen::TaskResult> out;
  for (const nlohmann::json& r : j) {
    if (!r.is_array() || r.size() < 2 || r.size() > 3 || !r[1].is_array() ||
        (r.size() == 3 && !r[2].is_string()))
      rd.bad("expected a result [witness, met] or [witness, met, sets]");
    gen::TaskResult res;
    res.witness = rd.witness(r[0]);
    for (const nlohmann::json& d : r[1]) {
      if (!d.is_array() || d.size() != 2) rd.bad("expected a discovery [PCs, pose]");
      res.met.push_back({rd.pcs(d[0]), rd.pose(d[1])});
    }
    if (r.size() == 3) res.sets = rd.sets(r[2].get_ref<const std::string&>());
    out.push_back(std::move(res));
  }
  return out;
}

// A digest of tasks: every field's bytes (little-endian machines alike), not their JSON, which
// would cost more than a chunk of screening itself.
std::uint64_t tasks_digest(const std::vector<gen::Task>& tasks) {
  std::string bytes;
  auto put = [&bytes](const auto& v) { bytes.append(reinterpret_cast<const char*>(&v), sizeof v); };
  for (const gen::Task& t : tasks) {
    put(static_cast<std::uint8_t>(t.kind));
    put(static_cast<std::uint8_t>(t.pcs.size()));
    for (const Pc& pc : t.pcs) put(pc.type), put(pc.a), put(pc.b);
    put(static_cast<std::uint32_t>(t.seeds.size()));
    for (const Mat3& R : t.seeds)
      for (int k = 0; k < 9; ++k) put(R(k / 3, k % 3));
    for (int k = 0; k < 9; ++k) put(t.pose.R_BA(k / 3, k % 3));
    for (int k = 0; k < 3; ++k) put(t.pose.t_BA(k));
  }
  return fnv1a(0xcbf29ce484222325ULL, bytes);
}

std::string hex64(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

}  // namespace

std::string chunk_text(std::size_t stage, std::size_t chunk,
                       const std::vector<gen::TaskResult>& results) {
  return nlohmann::json{{"stage", stage}, {"chunk", chunk}, {"results", task_results_json(results)}}
      .dump();
}

std::vector<gen::TaskResult> chunk_from_text(const std::string& text, const std::string& what,
                                             std::size_t& stage, std::size_t& chunk) {
  const Reader rd{[what](const std::string& problem) -> void {
    throw Error("reading " + what + ": " + problem);
  }};
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    rd.bad(std::string("not JSON (") + e.what() + ")");
  }
  auto count = [&](const char* key) {
    if (!j.contains(key) || !j.at(key).is_number_unsigned())
      rd.bad("expected {\"stage\", \"chunk\", \"results\"}");
    return j.at(key).get<std::size_t>();
  };
  if (!j.is_object() || !j.contains("results"))
    rd.bad("expected {\"stage\", \"chunk\", \"results\"}");
  stage = count("stage");
  chunk = count("chunk");
  return parse_task_results(j.at("results"), rd);
}

gen::ShardSpec parse_shard(const std::string& text) {
  int i = -1, k = -1;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &i, &k, &tail) != 2)
    throw Error("--shard '" + printable(text) + "': expected i/K, e.g. 0/4");
  if (k < 1 || k > kMaxShards)
    throw Error("--shard '" + printable(text) + "': K must be in 1.." + std::to_string(kMaxShards));
  if (i < 0 || i >= k)
    throw Error("--shard '" + printable(text) + "': i must be in 0.." + std::to_string(k - 1));
  gen::ShardSpec spec;
  spec.index = i;
  spec.count = k;
  return spec;
}

std::string run_fingerprint(const GenerateArgs& args) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  h = fnv1a(h, "cfgen shard v" + std::to_string(kVersion));
  for (const std::string* p : {&args.a_path, &args.b_path}) {
    std::string bytes, why;
    if (!read_input_file(*p, bytes, why)) throw Error("reading model '" + *p + "': " + why);
    h = fnv1a(h, bytes);
  }
  h = fnv1a(h, options_json(args).dump());
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

gen::ChunkStore open_checkpoint(const std::string& dir, const std::string& fingerprint,
                                const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw Error("checkpoint '" + dir + "': exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec)
    throw Error("checkpoint '" + dir + "': cannot create the directory (" + ec.message() + ")");
  const std::string manifest = (fs::path(dir) / "checkpoint.json").string();
  if (fs::exists(manifest, ec)) {
    const nlohmann::json j = read_json_file(manifest, "checkpoint", "; not a cfgen checkpoint");
    if (!j.is_object() || j.value("format", std::string()) != "cfgen checkpoint")
      throw Error("checkpoint '" + manifest + "': not a cfgen checkpoint");
    if (j.value("fingerprint", std::string()) != fingerprint)
      throw Error("checkpoint '" + dir +
                  "' was made from other models or options; use another directory, or remove it to "
                  "start over");
  } else {
    const nlohmann::json j = {
        {"format", "cfgen checkpoint"}, {"version", kVersion}, {"fingerprint", fingerprint}};
    write_outputs({{manifest, j.dump() + "\n"}}, inputs, "writing checkpoint");
  }
  gen::ChunkStore store;
  auto chunk_path = [dir](std::size_t stage, std::size_t chunk) {
    char name[64];
    std::snprintf(name, sizeof name, "stage%05zu_chunk%04zu.json", stage, chunk);
    return (fs::path(dir) / name).string();
  };
  // A chunk is kept with a digest of its tasks: a resumed run must be asking for the same work.
  auto digest = [](const std::vector<gen::Task>& tasks) { return hex64(tasks_digest(tasks)); };
  store.load = [=](std::size_t stage, std::size_t chunk, const std::vector<gen::Task>& tasks,
                   std::vector<gen::TaskResult>& out) {
    const std::string path = chunk_path(stage, chunk);
    std::error_code e;
    if (!fs::exists(path, e)) return false;
    const nlohmann::json j =
        read_json_file(path, "reading checkpoint chunk", "; remove it to compute the chunk again");
    if (!j.is_object() || j.value("fingerprint", std::string()) != fingerprint ||
        j.value("stage", std::size_t{0}) != stage || j.value("chunk", std::size_t{0}) != chunk ||
        j.value("tasks", std::string()) != digest(tasks))
      throw Error("reading checkpoint chunk '" + path +
                  "': made by another run (remove it to compute the chunk again)");
    const Reader rd{[&](const std::string& problem) -> void {
      throw Error("reading checkpoint chunk '" + path + "': " + problem +
                  " (remove it to compute the chunk again)");
    }};
    if (!j.contains("results")) rd.bad("missing \"results\"");
    out = parse_task_results(j.at("results"), rd);
    if (out.size() != tasks.size())
      rd.bad(std::to_string(out.size()) + " results for " + std::to_string(tasks.size()) +
             " tasks");
    return true;
  };
  store.save = [=](std::size_t stage, std::size_t chunk, const std::vector<gen::Task>& tasks,
                   const std::vector<gen::TaskResult>& res) {
    const nlohmann::json j = {{"fingerprint", fingerprint},
                              {"stage", stage},
                              {"chunk", chunk},
                              {"tasks", digest(tasks)},
                              {"results", task_results_json(res)}};
    write_outputs({{chunk_path(stage, chunk), j.dump() + "\n"}}, inputs, "writing checkpoint");
  };
  return store;
}

void remove_checkpoint(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> ours;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const bool chunk = name.rfind("stage", 0) == 0 && name.size() > 5 &&
                       name.compare(name.size() - 5, 5, ".json") == 0;
    if (chunk || name == "checkpoint.json") ours.push_back(it->path());
  }
  // The manifest last: a directory left half-removed is still a checkpoint.
  std::sort(ours.begin(), ours.end(), [](const fs::path& x, const fs::path& y) {
    return (x.filename() == "checkpoint.json") < (y.filename() == "checkpoint.json");
  });
  for (const fs::path& p : ours) fs::remove(p, ec);
  fs::remove(dir, ec);  // only when nothing else is in it
}

}  // namespace cf::tools
