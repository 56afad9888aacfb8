#include "cfgen/shard.hpp"

#include <cf/file_io.hpp>
#include <cf/types.hpp>

#include <nlohmann/json.hpp>

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <functional>
#include <set>

namespace cf::tools {
namespace {

constexpr const char* kFormat = "cfgen shard part";
// 2: a witness as in chunks, [found, pose (12), clearance, margin]; 3: the witness search
// climbs past obstacles and the neighbour rounds' tasks (the same tasks give other results,
// so the parts and checkpoints of version 2 are refused).
constexpr int kVersion = 3;
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
                      {"coplanar_tol_b", a.load_b.coplanar_rel_tol}};
  // Only when set, so that the fingerprints of runs without it are those of earlier builds.
  if (a.thorough) o["thorough"] = true;
  return o;
}

// The JSON document in file `path`; errors read "<what> '<path>': <reason><hint>".
nlohmann::json read_json_file(const std::string& path, const std::string& what, const std::string& hint = "") {
  std::string bytes, why;
  if (!read_input_file(path, bytes, why)) throw Error(what + " '" + path + "': " + why);
  try {
    return nlohmann::json::parse(bytes);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(what + " '" + path + "': not JSON (" + e.what() + ")" + hint);
  }
}

[[noreturn]] void bad_part(const std::string& path, const std::string& problem) {
  throw Error("reading shard part '" + path + "': " + problem);
}

template <class T>
T field(const nlohmann::json& j, const char* key, const std::string& path) {
  if (!j.is_object() || !j.contains(key)) bad_part(path, std::string("missing \"") + key + "\"");
  try {
    return j.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    bad_part(path, std::string("\"") + key + "\" has the wrong type");
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
      if (k < 9) p.R_BA(k / 3, k % 3) = v;
      else p.t_BA(k - 9) = v;
    }
    return p;
  }
  PcSet pcs(const nlohmann::json& j) const {
    if (!j.is_array() || j.empty() || j.size() > PcSet::kMaxPcs) bad("expected a set of 1 to 3 PCs");
    PcSet s;
    for (const nlohmann::json& pc : j) {
      if (!pc.is_array() || pc.size() != 3 || !pc[0].is_number_unsigned() || !pc[1].is_number_unsigned() ||
          !pc[2].is_number_unsigned() || pc[0].get<unsigned>() > static_cast<unsigned>(PcType::kEE))
        bad("expected a PC [type, a, b]");
      if (!s.insert(Pc{static_cast<PcType>(pc[0].get<int>()), pc[1].get<int>(), pc[2].get<int>()}))
        bad("a PC is repeated");
    }
    return s;
  }
  gen::Witness witness(const nlohmann::json& j) const {
    gen::Witness w;
    if (!j.is_array() || j.empty() || !j[0].is_boolean()) bad("expected a witness [found, ...]");
    w.found = j[0].get<bool>();
    if (!w.found) return w;
    if (j.size() != 4 || !j[2].is_number() || !j[3].is_number()) bad("expected [true, pose, clearance, margin]");
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

// [index, witness...] (witness_json with its index in front): doubles round-trip exactly.
nlohmann::json results_json(const std::vector<std::pair<std::size_t, gen::Witness>>& results) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [i, w] : results) {
    nlohmann::json r = witness_json(w);
    r.insert(r.begin(), i);
    out.push_back(std::move(r));
  }
  return out;
}

// The "results" array of `j`; `mine(i)` says whether candidate i may appear in this file.
std::vector<std::pair<std::size_t, gen::Witness>> parse_results(const nlohmann::json& j, const std::string& path,
                                                                 const std::string& what,
                                                                 const std::function<bool(std::size_t)>& mine) {
  auto bad = [&](const std::string& problem) { throw Error("reading " + what + " '" + path + "': " + problem); };
  if (!j.contains("results") || !j.at("results").is_array()) bad("missing \"results\" array");
  std::vector<std::pair<std::size_t, gen::Witness>> out;
  for (const nlohmann::json& r : j.at("results")) {
    const std::string where = "result " + std::to_string(out.size());
    if (!r.is_array() || r.size() < 2 || !r[0].is_number_unsigned()) bad(where + ": expected [index, found, ...]");
    const std::size_t i = r[0].get<std::size_t>();
    if (!mine(i)) bad(where + ": candidate " + std::to_string(i) + " does not belong in this file");
    const Reader rd{[&](const std::string& problem) -> void { bad(where + ": " + problem); }};
    out.push_back({i, rd.witness(nlohmann::json(r.begin() + 1, r.end()))});
  }
  return out;
}

nlohmann::json tasks_json(const std::vector<gen::Task>& tasks) {
  nlohmann::json out = nlohmann::json::array();
  for (const gen::Task& t : tasks) {
    nlohmann::json seeds = nlohmann::json::array();
    for (const Mat3& R : t.seeds) {
      Pose p;
      p.R_BA = R;
      seeds.push_back(pose_json(p));
    }
    out.push_back({static_cast<int>(t.kind), pcs_json(t.pcs), seeds, pose_json(t.pose)});
  }
  return out;
}

std::vector<gen::Task> parse_tasks(const nlohmann::json& j, const Reader& rd) {
  if (!j.is_array()) rd.bad("expected an array of tasks");
  std::vector<gen::Task> out;
  for (const nlohmann::json& t : j) {
    if (!t.is_array() || t.size() != 4 || !t[0].is_number_unsigned() ||
        t[0].get<unsigned>() > static_cast<unsigned>(gen::Task::Kind::kFindNear) ||
        !t[2].is_array())
      rd.bad("expected a task [kind, PCs, seeds, pose]");
    gen::Task task;
    task.kind = static_cast<gen::Task::Kind>(t[0].get<int>());
    task.pcs = rd.pcs(t[1]);
    for (const nlohmann::json& seed : t[2]) task.seeds.push_back(rd.pose(seed).R_BA);
    task.pose = rd.pose(t[3]);
    out.push_back(std::move(task));
  }
  return out;
}

nlohmann::json task_results_json(const std::vector<gen::TaskResult>& results) {
  nlohmann::json out = nlohmann::json::array();
  for (const gen::TaskResult& r : results) {
    nlohmann::json met = nlohmann::json::array();
    for (const gen::Discovery& d : r.met) met.push_back({pcs_json(d.pcs), pose_json(d.pose)});
    out.push_back({witness_json(r.witness), met});
  }
  return out;
}

std::vector<gen::TaskResult> parse_task_results(const nlohmann::json& j, const Reader& rd) {
  if (!j.is_array()) rd.bad("expected an array of results");
  std::vector<gen::TaskResult> out;
  for (const nlohmann::json& r : j) {
    if (!r.is_array() || r.size() != 2 || !r[1].is_array()) rd.bad("expected a result [witness, met]");
    gen::TaskResult res;
    res.witness = rd.witness(r[0]);
    for (const nlohmann::json& d : r[1]) {
      if (!d.is_array() || d.size() != 2) rd.bad("expected a discovery [PCs, pose]");
      res.met.push_back({rd.pcs(d[0]), rd.pose(d[1])});
    }
    out.push_back(std::move(res));
  }
  return out;
}

std::string hex64(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

}  // namespace

namespace {

// {"chunk": N, key: ...} as sent between ranks; `what` names it in errors.
const nlohmann::json& chunk_message(const std::string& text, const char* key, const Reader& rd, nlohmann::json& j,
                                    std::size_t& chunk) {
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    rd.bad(std::string("not JSON (") + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("chunk") || !j.at("chunk").is_number_unsigned() || !j.contains(key))
    rd.bad(std::string("expected {\"chunk\", \"") + key + "\"}");
  chunk = j.at("chunk").get<std::size_t>();
  return j.at(key);
}

Reader message_reader(const std::string& what) {
  return Reader{[what](const std::string& problem) -> void { throw Error("reading " + what + ": " + problem); }};
}

}  // namespace

std::string tasks_text(std::size_t chunk, const std::vector<gen::Task>& tasks) {
  return nlohmann::json{{"chunk", chunk}, {"tasks", tasks_json(tasks)}}.dump();
}

std::vector<gen::Task> tasks_from_text(const std::string& text, const std::string& what, std::size_t& chunk) {
  const Reader rd = message_reader(what);
  nlohmann::json j;
  return parse_tasks(chunk_message(text, "tasks", rd, j, chunk), rd);
}

std::string task_results_text(std::size_t chunk, const std::vector<gen::TaskResult>& results) {
  return nlohmann::json{{"chunk", chunk}, {"results", task_results_json(results)}}.dump();
}

std::vector<gen::TaskResult> task_results_from_text(const std::string& text, const std::string& what,
                                                    std::size_t& chunk) {
  const Reader rd = message_reader(what);
  nlohmann::json j;
  return parse_task_results(chunk_message(text, "results", rd, j, chunk), rd);
}

gen::ShardSpec parse_shard(const std::string& text) {
  int i = -1, k = -1;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &i, &k, &tail) != 2)
    throw Error("--shard '" + printable(text) + "': expected i/K, e.g. 0/4");
  if (k < 1 || k > kMaxShards)
    throw Error("--shard '" + printable(text) + "': K must be in 1.." + std::to_string(kMaxShards));
  if (i < 0 || i >= k) throw Error("--shard '" + printable(text) + "': i must be in 0.." + std::to_string(k - 1));
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

void write_part(const std::string& path, const ShardPart& part) {
  const nlohmann::json results = results_json(part.results);
  const nlohmann::json j = {{"format", kFormat},
                            {"version", kVersion},
                            {"shard", part.index},
                            {"shards", part.count},
                            {"fingerprint", part.fingerprint},
                            {"models",
                             {{"a", part.a_given}, {"b", part.b_given}, {"a_path", part.args.a_path},
                              {"b_path", part.args.b_path}}},
                            {"options", options_json(part.args)},
                            {"candidates", part.candidates},
                            {"results", results}};
  write_outputs({{path, j.dump() + "\n"}}, {part.args.a_path, part.args.b_path}, "writing shard part");
}

ShardPart read_part(const std::string& path) {
  const nlohmann::json j = read_json_file(path, "reading shard part");
  if (!j.is_object() || j.value("format", std::string()) != kFormat)
    bad_part(path, "not a cfgen shard part (no \"format\": \"cfgen shard part\")");
  const int version = field<int>(j, "version", path);
  if (version != kVersion)
    bad_part(path, "version " + std::to_string(version) + ", this cfgen reads version " + std::to_string(kVersion));
  ShardPart p;
  p.path = path;
  p.index = field<int>(j, "shard", path);
  p.count = field<int>(j, "shards", path);
  if (p.count < 1 || p.count > kMaxShards || p.index < 0 || p.index >= p.count)
    bad_part(path, "shard " + std::to_string(p.index) + "/" + std::to_string(p.count) + " is out of range");
  p.fingerprint = field<std::string>(j, "fingerprint", path);
  const nlohmann::json& m = j.contains("models") ? j.at("models") : nlohmann::json();
  p.a_given = field<std::string>(m, "a", path);
  p.b_given = field<std::string>(m, "b", path);
  p.args.a_path = field<std::string>(m, "a_path", path);
  p.args.b_path = field<std::string>(m, "b_path", path);
  const nlohmann::json& o = j.contains("options") ? j.at("options") : nlohmann::json();
  p.args.max_pcs = field<int>(o, "max_pcs", path);
  p.args.symmetry = field<bool>(o, "symmetry", path);
  p.args.thorough = o.contains("thorough") && field<bool>(o, "thorough", path);
  p.args.rel.touch_tol = field<double>(o, "touch_tol_rel", path);
  p.args.rel.min_clearance = field<double>(o, "min_clearance_rel", path);
  p.args.rel.good_clearance = field<double>(o, "good_clearance_rel", path);
  p.args.rel.min_margin = field<double>(o, "min_margin_rel", path);
  p.args.search.angle_margin = field<double>(o, "angle_margin_rad", path);
  p.args.search.theta_samples = field<int>(o, "theta_samples", path);
  p.args.search.max_rotations = field<int>(o, "max_rotations", path);
  p.args.search.max_piece_combinations = field<int>(o, "max_piece_combinations", path);
  p.args.load_a.units = field<std::string>(o, "units_a", path);
  p.args.load_b.units = field<std::string>(o, "units_b", path);
  p.args.load_a.coplanar_rel_tol = field<double>(o, "coplanar_tol_a", path);
  p.args.load_b.coplanar_rel_tol = field<double>(o, "coplanar_tol_b", path);
  p.candidates = field<std::size_t>(j, "candidates", path);
  p.results = parse_results(j, path, "shard part", [&](std::size_t i) {
    return i < p.candidates && i % static_cast<std::size_t>(p.count) == static_cast<std::size_t>(p.index);
  });
  return p;
}

std::vector<gen::Witness> gather_parts(const std::vector<ShardPart>& parts) {
  if (parts.empty()) throw Error("merging shards: no part given");
  const ShardPart& first = parts.front();
  std::set<int> seen;
  for (const ShardPart& p : parts) {
    if (p.fingerprint != first.fingerprint || p.count != first.count || p.candidates != first.candidates)
      throw Error("merging shards: '" + p.path + "' comes from another run than '" + first.path +
                  "' (other models, options or shard count)");
    if (!seen.insert(p.index).second)
      throw Error("merging shards: shard " + std::to_string(p.index) + "/" + std::to_string(p.count) +
                  " is given twice ('" + p.path + "')");
  }
  if (static_cast<int>(seen.size()) != first.count) {
    std::string missing;
    for (int i = 0, n = 0; i < first.count && n < 8; ++i)
      if (!seen.count(i)) missing += (n++ ? ", " : "") + std::to_string(i);
    throw Error("merging shards: " + std::to_string(first.count - static_cast<int>(seen.size())) + " of " +
                std::to_string(first.count) + " shards are missing (shard " + missing +
                (first.count - static_cast<int>(seen.size()) > 8 ? ", ..." : "") + ")");
  }
  std::vector<gen::Witness> all(first.candidates);
  std::vector<char> have(first.candidates, 0);
  for (const ShardPart& p : parts)
    for (const auto& [i, w] : p.results) {
      if (have[i]) throw Error("merging shards: '" + p.path + "' repeats candidate " + std::to_string(i));
      have[i] = 1;
      all[i] = w;
    }
  for (std::size_t i = 0; i < have.size(); ++i)
    if (!have[i])
      throw Error("merging shards: no part holds candidate " + std::to_string(i) + " (shard " +
                  std::to_string(i % static_cast<std::size_t>(first.count)) + " is incomplete)");
  return all;
}

gen::ChunkStore open_checkpoint(const std::string& dir, const std::string& fingerprint,
                               const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw Error("checkpoint '" + dir + "': exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw Error("checkpoint '" + dir + "': cannot create the directory (" + ec.message() + ")");
  const std::string manifest = (fs::path(dir) / "checkpoint.json").string();
  if (fs::exists(manifest, ec)) {
    const nlohmann::json j = read_json_file(manifest, "checkpoint", "; not a cfgen checkpoint");
    if (!j.is_object() || j.value("format", std::string()) != "cfgen checkpoint")
      throw Error("checkpoint '" + manifest + "': not a cfgen checkpoint");
    if (j.value("fingerprint", std::string()) != fingerprint)
      throw Error("checkpoint '" + dir +
                  "' was made from other models or options; use another directory, or remove it to start over");
  } else {
    const nlohmann::json j = {{"format", "cfgen checkpoint"}, {"version", kVersion}, {"fingerprint", fingerprint}};
    write_outputs({{manifest, j.dump() + "\n"}}, inputs, "writing checkpoint");
  }
  gen::ChunkStore store;
  auto chunk_path = [dir](std::size_t stage, std::size_t chunk) {
    char name[64];
    std::snprintf(name, sizeof name, "stage%05zu_chunk%04zu.json", stage, chunk);
    return (fs::path(dir) / name).string();
  };
  // A chunk is kept with a digest of its tasks: a resumed run must be asking for the same work.
  auto digest = [](const std::vector<gen::Task>& tasks) { return hex64(fnv1a(0xcbf29ce484222325ULL, tasks_json(tasks).dump())); };
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
      throw Error("reading checkpoint chunk '" + path + "': made by another run (remove it to compute the chunk again)");
    const Reader rd{[&](const std::string& problem) -> void {
      throw Error("reading checkpoint chunk '" + path + "': " + problem + " (remove it to compute the chunk again)");
    }};
    if (!j.contains("results")) rd.bad("missing \"results\"");
    out = parse_task_results(j.at("results"), rd);
    if (out.size() != tasks.size())
      rd.bad(std::to_string(out.size()) + " results for " + std::to_string(tasks.size()) + " tasks");
    return true;
  };
  store.save = [=](std::size_t stage, std::size_t chunk, const std::vector<gen::Task>& tasks,
                   const std::vector<gen::TaskResult>& res) {
    const nlohmann::json j = {{"fingerprint", fingerprint}, {"stage", stage}, {"chunk", chunk},
                              {"tasks", digest(tasks)}, {"results", task_results_json(res)}};
    write_outputs({{chunk_path(stage, chunk), j.dump() + "\n"}}, inputs, "writing checkpoint");
  };
  return store;
}

int run_merge(const std::vector<std::string>& part_paths, const std::string& out_path, int threads,
              bool quiet) {
  std::vector<ShardPart> parts;
  for (const std::string& p : part_paths) parts.push_back(read_part(p));
  const std::vector<gen::Witness> first_pairs = gather_parts(parts);
  GenerateArgs args = parts.front().args;
  args.out_path = out_path;
  args.threads = threads;
  args.quiet = quiet;
  if (run_fingerprint(args) != parts.front().fingerprint)
    throw Error("merging shards: the models '" + args.a_path + "' and '" + args.b_path +
                "' are not the files the shards read (they changed since)");
  args.a_label = parts.front().a_given;
  args.b_label = parts.front().b_given;
  args.first_pairs = &first_pairs;
  std::vector<std::string> inputs = part_paths;
  check_output_path(out_path, inputs, "writing graph");
  return run_generate(args);
}

}  // namespace cf::tools
