#include "swirl/io/csv.hpp"

#include <iterator>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"

namespace swirl::io {
namespace {

// RFC 4180 quoting, needed only if an extra field's name has a comma or quote.
std::string csv_cell(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

}  // namespace

template <class Real>
void write_csv(const std::filesystem::path& path, const ParticleSet<Real>& particles, double time) {
  const auto fields = particles.fields();
  // fmt's "{}" is the shortest representation that reads back to the same value.
  std::string out = fmt::format("# time = {}\nid,x,y,z", time);
  for (const auto& f : fields) {
    if (f.name == "position" || f.internal) continue;
    if (f.components == 1) {
      out += ',' + csv_cell(f.name);
    } else {
      for (const char* axis : {"_x", "_y", "_z"}) out += ',' + csv_cell(std::string(f.name) + axis);
    }
  }
  const auto int_fields = particles.int_fields();
  for (const auto& f : int_fields)
    if (!f.internal) out += ',' + csv_cell(f.name);
  out += '\n';

  auto sink = std::back_inserter(out);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    fmt::format_to(sink, "{},{},{},{}", particles.id[i], particles.position.x[i], particles.position.y[i],
                   particles.position.z[i]);
    for (const auto& f : fields) {
      if (f.name == "position" || f.internal) continue;
      for (int c = 0; c < f.components; ++c) fmt::format_to(sink, ",{}", f.data[c][i]);
    }
    for (const auto& f : int_fields)
      if (!f.internal) fmt::format_to(sink, ",{}", f.data[0][i]);
    out += '\n';
  }
  write_file_atomic(path, out);
}

template void write_csv<float>(const std::filesystem::path&, const ParticleSet<float>&, double);
template void write_csv<double>(const std::filesystem::path&, const ParticleSet<double>&, double);

}  // namespace swirl::io
