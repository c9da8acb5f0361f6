#include "swirl/io/frame_names.hpp"

#include <system_error>

#include <fmt/format.h>

namespace swirl::io {
namespace fs = std::filesystem;

std::string frame_file_name(std::string_view series, std::uint64_t index, std::string_view extension) {
  return fmt::format("{}_{:06d}{}", series, index, extension);
}

std::optional<std::uint64_t> frame_index(const fs::path& file, std::string_view series) {
  const std::string stem = file.stem().string();
  const std::size_t digits_at = series.size() + 1;
  if (stem.size() <= digits_at || stem.size() > digits_at + 18 || stem.compare(0, series.size(), series) != 0 ||
      stem[series.size()] != '_')
    return std::nullopt;
  std::uint64_t n = 0;
  for (std::size_t i = digits_at; i < stem.size(); ++i) {
    if (stem[i] < '0' || stem[i] > '9') return std::nullopt;
    n = n * 10 + static_cast<std::uint64_t>(stem[i] - '0');
  }
  return n;
}

std::optional<int> frame_part_type(const fs::path& frame) {
  if (frame_index(frame, kBoundarySeries)) return 2;
  return std::nullopt;
}

std::optional<fs::path> boundary_frame_for(const fs::path& particles_frame) {
  const auto n = frame_index(particles_frame, kParticleSeries);
  if (!n) return std::nullopt;
  const fs::path dir = particles_frame.parent_path();
  const std::string extension = particles_frame.extension().string();
  // Moving boundaries: the frame of the same index (the common case, one stat).
  if (fs::path same = dir / frame_file_name(kBoundarySeries, *n, extension); fs::is_regular_file(same)) return same;
  std::optional<fs::path> best;
  std::uint64_t best_index = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path& p = it->path();
    if (p.extension() != extension) continue;
    const auto m = frame_index(p, kBoundarySeries);
    if (!m || *m > *n || (best && *m <= best_index)) continue;
    if (!it->is_regular_file(ec)) continue;
    best = dir / p.filename();
    best_index = *m;
  }
  return best;
}

fs::path boundary_file_beside(const fs::path& frame) {
  const std::string extension = frame.extension().string();
  if (const auto n = frame_index(frame, kParticleSeries))
    return frame.parent_path() / frame_file_name(kBoundarySeries, *n, extension);
  return frame.parent_path() / (frame.stem().string() + "_boundary" + extension);
}

}  // namespace swirl::io
