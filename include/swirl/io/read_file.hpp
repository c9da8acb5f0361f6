// Reading a whole input file, the one way every reader of swirl does it.
//
// Only a regular file is read: a FIFO, a device, a socket or a directory is
// refused at once (opened without blocking, then fstat'ed), so a reader never
// hangs on a pipe nobody writes to, or reads /dev/zero forever. And never more
// than `max_bytes` is read: the size a valid file of that kind can have, so a
// huge or still-growing file is refused instead of exhausting memory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "swirl/io/atomic_file.hpp"  // IoError

namespace swirl::io {

// Upper bounds of the files swirl reads. Text files are bounded by what swirl
// or a person writes; frames and checkpoints by what fits in this machine's
// memory (a larger file could not be held to be read anyway).
inline constexpr std::uintmax_t kMiB = std::uintmax_t{1} << 20;
inline constexpr std::uintmax_t kMaxSceneBytes = 256 * kMiB;   // a scene, with long particle lists
inline constexpr std::uintmax_t kMaxSeriesBytes = 256 * kMiB;  // a .pvd: millions of frames
inline constexpr std::uintmax_t kMaxTextBytes = 1024 * kMiB;   // a CSV log such as diagnostics.csv
inline constexpr std::uintmax_t kMaxFontBytes = 64 * kMiB;     // the largest TrueType fonts are ~30 MiB
// The machine's physical memory: the bound for .vtp frames and checkpoints.
std::uintmax_t max_particle_file_bytes();

// The whole content of `path`. Throws IoError naming the file if it cannot be
// opened or read, is not a regular file (FIFO, device, socket, directory), or
// holds more than `max_bytes` bytes (also when it grows past them while read).
std::string read_regular_file(const std::filesystem::path& path, std::uintmax_t max_bytes);

}  // namespace swirl::io
