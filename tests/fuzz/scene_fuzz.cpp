// libFuzzer target: bytes -> swirl::scene::parse_scene (+ one override from a
// leading "#set KEY=VALUE" line), then scene_hash and make_particles for small
// scenes. See scene_replay.hpp; run with .ci/fuzz.sh or
//   build-fuzz/scene_fuzz -dict=tests/fuzz/scene.dict CORPUS_COPY tests/fuzz/corpus/scene
// SWIRL_FUZZ_STRICT=1 also requires finite particles from every accepted scene.
// fuzz-modules: scene gravity io
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz/scene_replay.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool strict = [] {
    const char* s = std::getenv("SWIRL_FUZZ_STRICT");
    return s && *s && *s != '0';
  }();
  (void)swirl::fuzz::replay_scene(std::string_view(reinterpret_cast<const char*>(data), size), strict);
  return 0;
}
