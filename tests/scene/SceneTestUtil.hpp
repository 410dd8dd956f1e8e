#pragma once
// Helpers shared by the scene tests: reading files of the source tree.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace rcfd::test {

inline std::string sourcePath(const std::string& relative) { return std::string(RCFD_SOURCE_DIR) + "/" + relative; }

inline std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The example scenes (examples/*.json), sorted by name.
inline std::vector<std::string> exampleFiles() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(sourcePath("examples"))) {
    if (entry.path().extension() == ".json") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace rcfd::test
