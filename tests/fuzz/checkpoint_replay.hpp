// One input of the checkpoint fuzzer, through the real API: parse_checkpoint()
// for both precisions, and read_checkpoint_header() on the same bytes as a file.
// Each may accept the bytes or throw IoError naming the file.
//
// A checkpoint ends in a checksum of everything before it, so nearly every
// mutated input would stop there. Each input is therefore parsed twice: as it
// is, and with its last 8 bytes replaced by the right checksum (FNV-1a 64 of
// the rest, as docs and include/swirl/io/checkpoint.hpp define it), so that
// the parser behind the checksum is fuzzed too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz/replay.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/checkpoint.hpp"

namespace swirl::fuzz {

inline constexpr std::string_view kCheckpointName = "fuzz.ckp";

inline std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t h = 0xcbf29ce484222325u;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3u;
  }
  return h;
}

// The bytes with a correct trailing checksum (unchanged if shorter than 8).
inline std::string with_checksum(std::string_view bytes) {
  std::string out(bytes);
  if (out.size() < 8) return out;
  const std::uint64_t sum = fnv1a64(std::string_view(out).substr(0, out.size() - 8));
  std::memcpy(out.data() + out.size() - 8, &sum, 8);
  return out;
}

template <class Real>
std::optional<std::string> replay_checkpoint_as(std::string_view bytes) {
  ParticleSet<Real> particles;
  io::CheckpointValues values;
  try {
    const io::CheckpointHeader h = io::parse_checkpoint<Real>(bytes, kCheckpointName, particles, values);
    require(h.real_bytes == sizeof(Real), "accepted a checkpoint of the other precision");
    require(particles.size() == h.particles, "particle count differs from the header");
    require(particles.id.size() == particles.size(), "ids not one per particle");
    for (const auto& f : particles.fields())
      for (int c = 0; c < f.components; ++c) require(f.data[c] != nullptr || particles.empty(), "field without data");
    for (const auto& f : particles.int_fields())
      require(f.data[0] != nullptr || particles.empty(), "integer field without data");
    require(h.version >= io::kOldestReadableCheckpointVersion && h.version <= io::kCheckpointVersion,
            "accepted a format version this swirl does not read");
  } catch (const io::IoError& e) {
    check_error_message(e.what(), kCheckpointName);
    return std::string(e.what());
  }
  return std::nullopt;
}

// Both precisions, as the file is and with its checksum fixed.
inline void replay_checkpoint(std::string_view bytes) {
  const std::string fixed = with_checksum(bytes);
  for (const std::string_view b : {bytes, std::string_view(fixed)}) {
    (void)replay_checkpoint_as<float>(b);
    (void)replay_checkpoint_as<double>(b);
  }
}

inline std::optional<std::string> replay_checkpoint_header(const std::filesystem::path& path) {
  try {
    const io::CheckpointHeader h = io::read_checkpoint_header(path);
    require(h.real_bytes == 4 || h.real_bytes == 8, "header with a bad precision accepted");
  } catch (const io::IoError& e) {
    check_error_message(e.what(), path.string());
    return std::string(e.what());
  }
  return std::nullopt;
}

}  // namespace swirl::fuzz
