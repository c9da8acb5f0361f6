// libFuzzer target: bytes -> swirl::io::parse_checkpoint (float and double; as
// given and with the checksum fixed, see checkpoint_replay.hpp) and
// read_checkpoint_header on the bytes as a file. Run with .ci/fuzz.sh or
//   build-fuzz/checkpoint_fuzz CORPUS_COPY tests/fuzz/corpus/checkpoint
// fuzz-modules: io
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz/checkpoint_replay.hpp"
#include "fuzz/memfile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static swirl::fuzz::MemFile file;
  swirl::fuzz::replay_checkpoint(std::string_view(reinterpret_cast<const char*>(data), size));
  (void)swirl::fuzz::replay_checkpoint_header(file.write(data, size));
  return 0;
}
