// scene_keys_doc: the key tables of docs/scenes.md, generated from the scene
// key declarations (include/swirl/scene/keys.hpp).
//
//   scene_keys_doc                 prints every table, each under its section name
//   scene_keys_doc SECTION         prints one table ("simulation", "nbody", "lattice", ...)
//   scene_keys_doc --write FILE    rewrites the generated regions of FILE in place
//   scene_keys_doc --check FILE    exits 1 (and says which) when FILE's regions are stale
//
// tests/scene/keys_doc_test.cpp runs the same check in the test suite.
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

#include "swirl/scene/keys.hpp"

namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int usage() {
  std::fputs("usage: scene_keys_doc [SECTION | --write FILE | --check FILE]\n", stderr);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace swirl::scene;
  try {
    if (argc == 1) {
      for (const auto section : key_table_sections())
        std::printf("%.*s\n%s\n", static_cast<int>(section.size()), section.data(), key_table_markdown(section).c_str());
      return 0;
    }
    const std::string_view first = argv[1];
    if (argc == 2 && !first.starts_with("--")) {
      std::fputs(key_table_markdown(first).c_str(), stdout);
      return 0;
    }
    if (argc != 3 || (first != "--write" && first != "--check")) return usage();
    const std::string path = argv[2];
    const std::string text = read_text(path);
    const std::string generated = with_generated_key_tables(text);
    if (generated == text) return 0;
    if (first == "--check") {
      std::fprintf(stderr, "%s: the scene key tables are stale; run scene_keys_doc --write %s\n", path.c_str(),
                   path.c_str());
      return 1;
    }
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << generated;
    if (!out) throw std::runtime_error("cannot write " + path);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_keys_doc: %s\n", e.what());
    return 1;
  }
}
