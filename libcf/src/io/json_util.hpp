#pragma once
// Private helpers for reading JSON with errors that name the source and the JSON pointer.

#include <cf/types.hpp>

#include <nlohmann/json.hpp>

#include <string>

namespace cf::internal {

using json = nlohmann::json;

/// Where a JSON value sits: the source (file name) and its JSON pointer.
struct JsonWhere {
  const std::string& source;
  std::string pointer;
  JsonWhere operator/(const std::string& key) const { return {source, pointer + "/" + key}; }
  JsonWhere operator/(std::size_t i) const { return {source, pointer + "/" + std::to_string(i)}; }
  std::string str() const { return "'" + source + "' at " + (pointer.empty() ? "/" : pointer); }
};

[[noreturn]] inline void json_fail(const JsonWhere& w, const std::string& what) {
  throw Error("reading " + w.str() + ": " + what);
}

inline std::string json_short(const json& j) {
  std::string s = j.dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

inline const json& json_member(const json& j, const char* key, const JsonWhere& w) {
  if (!j.is_object()) json_fail(w, "expected an object, got " + json_short(j));
  auto it = j.find(key);
  if (it == j.end()) json_fail(w, std::string("missing member \"") + key + "\"");
  return *it;
}

inline const json& json_array(const json& j, const JsonWhere& w) {
  if (!j.is_array()) json_fail(w, "expected an array, got " + json_short(j));
  return j;
}

inline double json_number(const json& j, const JsonWhere& w) {
  if (!j.is_number()) json_fail(w, "expected a number, got " + json_short(j));
  return j.get<double>();
}

inline int json_index(const json& j, const JsonWhere& w) {
  if (!j.is_number_integer() || j.get<long long>() < 0 || j.get<long long>() > 2147483647LL)
    json_fail(w, "expected a non-negative integer index, got " + json_short(j));
  return static_cast<int>(j.get<long long>());
}

inline std::string json_string(const json& j, const JsonWhere& w) {
  if (!j.is_string()) json_fail(w, "expected a string, got " + json_short(j));
  return j.get<std::string>();
}

inline Vec3 json_vec3(const json& j, const JsonWhere& w) {
  json_array(j, w);
  if (j.size() != 3) json_fail(w, "expected 3 numbers, got " + json_short(j));
  return {json_number(j[0], w / 0), json_number(j[1], w / 1), json_number(j[2], w / 2)};
}

}  // namespace cf::internal
