// libFuzzer target: bytes -> a file -> swirl::io::read_vtp and read_pvd (they
// share the XML scanner). See io_replay.hpp; run with .ci/fuzz.sh or
//   build-fuzz/vtp_fuzz -dict=tests/fuzz/vtp.dict CORPUS_COPY tests/fuzz/corpus/vtp
// fuzz-modules: io
#include <cstddef>
#include <cstdint>

#include "fuzz/io_replay.hpp"
#include "fuzz/memfile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static swirl::fuzz::MemFile file;
  const auto& path = file.write(data, size);
  (void)swirl::fuzz::replay_vtp(path);
  (void)swirl::fuzz::replay_pvd(path);
  return 0;
}
