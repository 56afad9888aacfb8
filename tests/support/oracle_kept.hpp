#pragma once
// The model pairs the recall test keeps (tests/oracle, fixture oracle_samples), one directory
// each with A.off, B.off, G.json and samples.csv, for the tests that reuse them.

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace cf::test {

/// Where the kept pairs are: $CF_ORACLE_KEEP_DIR when set, else `default_dir`.
inline std::filesystem::path kept_oracle_dir(const std::string& default_dir) {
  const char* env = std::getenv("CF_ORACLE_KEEP_DIR");
  return env != nullptr ? env : default_dir;
}

/// The kept pairs' directories under `kept`, sorted; empty when the recall test has not run.
inline std::vector<std::filesystem::path> kept_oracle_pairs(const std::filesystem::path& kept) {
  namespace fs = std::filesystem;
  std::vector<fs::path> dirs;
  if (fs::is_directory(kept))
    for (const auto& e : fs::directory_iterator(kept))
      if (fs::exists(e.path() / "samples.csv") && fs::exists(e.path() / "G.json"))
        dirs.push_back(e.path());
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

}  // namespace cf::test
