#pragma once
// PC lists as text ("type:a:b" items, as cf::to_string writes them joined by ';' and the
// oracle's samples.csv by ' ') compared as sets. Part of tests/support.

#include <set>
#include <sstream>
#include <string>

namespace cf::testdata {

/// The items of `list` separated by `sep`, as a set (empty items skipped).
inline std::set<std::string> pc_strings(const std::string& list, char sep) {
  std::set<std::string> out;
  std::string item;
  std::istringstream in(list);
  while (std::getline(in, item, sep))
    if (!item.empty()) out.insert(item);
  return out;
}

}  // namespace cf::testdata
