// For the regression tests: the files of a fuzz target's folders.
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace swirl::fuzz {

// The regular files of `dir`, sorted; notes such as README.md and dot files
// are not inputs. A missing or unreadable folder, or one without inputs, throws
// std::runtime_error naming it: a replay of nothing would pass whatever the
// reader does, so a renamed or mistyped folder must fail the test instead.
inline std::vector<std::filesystem::path> input_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec);
  if (ec) throw std::runtime_error("cannot list the replay folder " + dir.string() + ": " + ec.message());
  for (const auto& entry : it) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || name.starts_with(".") || name.ends_with(".md")) continue;
    out.push_back(entry.path());
  }
  if (out.empty()) throw std::runtime_error("the replay folder " + dir.string() + " holds no inputs");
  std::sort(out.begin(), out.end());
  return out;
}

inline std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace swirl::fuzz
