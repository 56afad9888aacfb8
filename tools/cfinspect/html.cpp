// cfinspect --html (see html.hpp). Only the checks whose failure should stop cfinspect are
// here: the page parses the CSVs again itself, since it can also open them from disk.
#include "html.hpp"

#include <cf/types.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

namespace cf::inspect {
namespace {

constexpr std::string_view kReplayHeader = "t,cf,pcs,motion,Fx,Fy,Fz,Mx,My,Mz";
constexpr std::string_view kTrajectoryHeader = "t,tx,ty,tz,qw,qx,qy,qz";

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(s);
  while (std::getline(in, item, sep)) out.push_back(item);
  if (!s.empty() && s.back() == sep) out.emplace_back();
  return out;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out = split(text, '\n');
  for (std::string& l : out)
    if (!l.empty() && l.back() == '\r') l.pop_back();
  while (!out.empty() && out.back().empty()) out.pop_back();
  return out;
}

bool parse_long(const std::string& s, long long& v) {
  try {
    std::size_t used = 0;
    v = std::stoll(s, &used);
    return used == s.size();
  } catch (const std::exception&) {
    return false;
  }
}

std::string where(const std::string& path, std::size_t line) {
  return "replay '" + path + "' line " + std::to_string(line) + ": ";
}

// Header, field counts and CF ids: the faults that would make the page show nothing useful.
std::size_t check_replay(const std::string& path, const std::string& text, std::size_t num_cfs) {
  const auto ls = lines(text);
  if (ls.empty() || ls[0].compare(0, kReplayHeader.size(), kReplayHeader) != 0)
    throw Error("replay '" + path + "': not a cfreplay CSV (the header must start with '" +
                std::string(kReplayHeader) + "')");
  const std::size_t fields = split(ls[0], ',').size();
  for (std::size_t i = 1; i < ls.size(); ++i) {
    const auto f = split(ls[i], ',');
    if (f.size() != fields)
      throw Error(where(path, i + 1) + std::to_string(f.size()) + " fields, expected " +
                  std::to_string(fields));
    long long cf = 0;
    if (!parse_long(f[1], cf) || cf < -1 || cf >= static_cast<long long>(num_cfs))
      throw Error(where(path, i + 1) + "CF '" + f[1].substr(0, 20) +
                  "' is not a CF of the graph (" + std::to_string(num_cfs) + " CFs)");
  }
  if (ls.size() < 2) throw Error("replay '" + path + "': no rows after the header");
  return ls.size() - 1;
}

std::size_t check_trajectory(const std::string& path, const std::string& text) {
  const auto ls = lines(text);
  if (ls.empty() || ls[0] != kTrajectoryHeader)
    throw Error("trajectory '" + path + "': the header must be '" + std::string(kTrajectoryHeader) +
                "'");
  for (std::size_t i = 1; i < ls.size(); ++i)
    if (split(ls[i], ',').size() != 8)
      throw Error("trajectory '" + path + "' line " + std::to_string(i + 1) +
                  ": expected 8 fields");
  return ls.size() - 1;
}

// JSON text inside <script>: '<' can only stand inside a JSON string, where \u003c means the
// same, so no "</script>" or "<!--" in the data can end or change the element.
std::string script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (char c : json) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

std::string data_script(const char* id, const std::string& json) {
  return std::string("<script id=\"") + id + "\" type=\"application/json\">" + script_safe(json) +
         "</script>\n";
}

std::string json_string(const std::string& text) {
  return nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

std::string read_text_file(const std::string& path, const char* what) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st))
    throw Error(std::string(what) + " '" + path + "': no such file");
  if (!std::filesystem::is_regular_file(st))
    throw Error(std::string(what) + " '" + path + "': not a regular file");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  if (!in || !(s << in.rdbuf())) {
    if (in && std::filesystem::file_size(path, ec) == 0 && !ec) return {};
    throw Error(std::string(what) + " '" + path + "': cannot read it");
  }
  return s.str();
}

std::string viewer_html(const ViewerInputs& in) {
  const char* page = viewer_page();
  if (!page)
    throw Error(
        "--html: this cfinspect was built without the browser viewer (it needs Node.js and `npm "
        "ci` in "
        "tools/cfinspect/viewer before configuring; bash scripts/setup.sh does both)");
  nlohmann::json meta = {{"graph", in.graph_path}};
  if (in.initial_cf >= 0) meta["cf"] = in.initial_cf;
  std::string data = data_script("cf-graph", in.graph_json);
  if (!in.replay_path.empty()) {
    const std::string replay = read_text_file(in.replay_path, "replay");
    const std::size_t rows = check_replay(in.replay_path, replay, in.num_cfs);
    meta["replay"] = in.replay_path;
    data += data_script("cf-replay", json_string(replay));
    if (!in.trajectory_path.empty()) {
      const std::string poses = read_text_file(in.trajectory_path, "trajectory");
      const std::size_t n = check_trajectory(in.trajectory_path, poses);
      if (n != rows)
        throw Error("trajectory '" + in.trajectory_path + "': " + std::to_string(n) +
                    " poses, but replay '" + in.replay_path + "' has " + std::to_string(rows) +
                    " rows (was it replayed from this trajectory?)");
      meta["trajectory"] = in.trajectory_path;
      data += data_script("cf-trajectory", json_string(poses));
    }
  }
  data +=
      data_script("cf-meta", meta.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  std::string html = page;
  const std::string marker = "<!--CF_DATA-->";
  const std::size_t at = html.find(marker);
  if (at == std::string::npos)
    throw Error("--html: the built-in page has no data marker (a build fault)");
  html.replace(at, marker.size(), data);
  return html;
}

}  // namespace cf::inspect
