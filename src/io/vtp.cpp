#include "swirl/io/vtp.hpp"

#include <algorithm>
#include <bit>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>

#include "detail.hpp"
#include "swirl/io/read_file.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::io {
namespace {

namespace fs = std::filesystem;
using detail::Malformed;

// The appended blocks are the in-memory bytes, and VtpArray hands raw bytes
// back to callers: both are only right on a little-endian host.
static_assert(std::endian::native == std::endian::little, "the .vtp writer and reader assume a little-endian host");
static_assert(std::numeric_limits<float>::is_iec559 && std::numeric_limits<double>::is_iec559);

template <class T>
constexpr const char* vtk_type() {
  if constexpr (std::is_same_v<T, float>) return "Float32";
  else if constexpr (std::is_same_v<T, double>) return "Float64";
  else if constexpr (std::is_same_v<T, std::uint64_t>) return "UInt64";
  else if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  else {
    static_assert(std::is_same_v<T, std::int64_t>);
    return "Int64";
  }
}

// The XML part and the appended data are built side by side; each array's
// offset is where its block starts in `data`.
class VtpBuilder {
 public:
  // Adds the DataArray element and reserves its block; returns where its
  // `count` values of type T go.
  template <class T>
  char* array(std::string_view indent, std::string_view name, int components, std::size_t count,
              std::string_view extra_attributes = {}) {
    xml_ += fmt::format("{}<DataArray type=\"{}\"", indent, vtk_type<T>());
    if (!name.empty()) xml_ += fmt::format(" Name=\"{}\"", detail::xml_escape(name));
    if (components != 1) xml_ += fmt::format(" NumberOfComponents=\"{}\"", components);
    xml_ += fmt::format("{} format=\"appended\" offset=\"{}\"/>\n", extra_attributes, data_.size());

    const std::uint64_t bytes = count * sizeof(T);
    const std::size_t at = data_.size();
    data_.resize(at + sizeof bytes + count * sizeof(T));
    std::memcpy(data_.data() + at, &bytes, sizeof bytes);
    return data_.data() + at + sizeof bytes;
  }

  void line(std::string_view text) {
    xml_ += text;
    xml_ += '\n';
  }

  std::string finish() && {
    xml_ += "  <AppendedData encoding=\"raw\">\n   _";
    xml_ += data_;
    xml_ += "\n  </AppendedData>\n</VTKFile>\n";
    return std::move(xml_);
  }

 private:
  std::string xml_;
  std::string data_;
};

template <class T>
void put(char*& out, T value) {
  std::memcpy(out, &value, sizeof value);
  out += sizeof value;
}

// T: Real for a real field, std::int32_t for an integer one (an Int32 array).
template <class T>
void put_field(VtpBuilder& b, std::string_view indent, const FieldView<const T>& f, std::size_t n,
               std::string_view name) {
  char* out = b.array<T>(indent, name, f.components, n * static_cast<std::size_t>(f.components));
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < f.components; ++c) put(out, f.data[c][i]);
}

// ---- reading ---------------------------------------------------------------

std::size_t type_size(std::string_view type) {
  if (type == "Int8" || type == "UInt8") return 1;
  if (type == "Int16" || type == "UInt16") return 2;
  if (type == "Int32" || type == "UInt32" || type == "Float32") return 4;
  if (type == "Int64" || type == "UInt64" || type == "Float64") return 8;
  throw Malformed("unknown DataArray type '" + std::string(type.substr(0, 40)) + "'");
}

struct ArrayRef {
  std::string section;  // FieldData, PointData, Points or Verts
  std::string name;
  std::string type;
  int components = 1;
  std::uint64_t offset = 0;
  std::optional<std::uint64_t> tuples;  // NumberOfTuples, if given
};

void expect_attribute(const detail::XmlTag& tag, std::string_view key, std::string_view value) {
  const std::string& v = tag.get(key);
  if (v != value)
    throw Malformed(fmt::format("<{}> has {}=\"{}\", expected \"{}\"", tag.name, key, v.substr(0, 40), value));
}

ArrayRef parse_data_array(const detail::XmlTag& tag, const std::string& section) {
  ArrayRef a;
  a.section = section;
  a.type = tag.get("type");
  (void)type_size(a.type);  // rejects unknown types before any data are looked at
  if (const std::string* name = tag.find("Name")) a.name = *name;
  if (const std::string* c = tag.find("NumberOfComponents")) {
    a.components = detail::parse_number<int>(*c, "NumberOfComponents");
    if (a.components < 1) throw Malformed("NumberOfComponents must be positive");
  }
  if (const std::string* t = tag.find("NumberOfTuples"))
    a.tuples = detail::parse_number<std::uint64_t>(*t, "NumberOfTuples");
  if (const std::string* c = tag.find("compressor"); c && !c->empty())
    throw Malformed("compressed arrays are not supported");
  expect_attribute(tag, "format", "appended");
  a.offset = detail::parse_number<std::uint64_t>(tag.get("offset"), "offset");
  return a;
}

struct Header {
  std::uint64_t num_points = 0, num_verts = 0;
  std::vector<ArrayRef> arrays;
  std::size_t data_start = 0;  // index of the byte after '_'
};

// Walks the XML up to <AppendedData> and checks that it has the structure the
// writer produces.
Header parse_header(std::string_view text) {
  Header h;
  detail::XmlScanner scan(text);
  std::vector<std::string> open;
  bool seen_root = false, seen_piece = false, seen_points = false;
  while (auto tag = scan.next()) {
    if (tag->closing) {
      if (open.empty() || open.back() != tag->name) throw Malformed("unexpected </" + tag->name + ">");
      open.pop_back();
      continue;
    }
    const std::string& name = tag->name;
    const std::string parent = open.empty() ? "" : open.back();
    auto require_parent = [&](std::initializer_list<std::string_view> allowed) {
      for (auto p : allowed)
        if (parent == p) return;
      throw Malformed(fmt::format("<{}> inside <{}>", name, parent));
    };

    if (name == "VTKFile") {
      if (seen_root || !parent.empty()) throw Malformed("more than one <VTKFile>");
      seen_root = true;
      expect_attribute(*tag, "type", "PolyData");
      expect_attribute(*tag, "byte_order", "LittleEndian");
      expect_attribute(*tag, "header_type", "UInt64");
      if (const std::string* c = tag->find("compressor"); c && !c->empty())
        throw Malformed("compressed files are not supported");
    } else if (name == "PolyData") {
      require_parent({"VTKFile"});
    } else if (name == "Piece") {
      require_parent({"PolyData"});
      if (seen_piece) throw Malformed("more than one <Piece>");
      seen_piece = true;
      h.num_points = detail::parse_number<std::uint64_t>(tag->get("NumberOfPoints"), "NumberOfPoints");
      if (const std::string* v = tag->find("NumberOfVerts"))
        h.num_verts = detail::parse_number<std::uint64_t>(*v, "NumberOfVerts");
      for (const char* cells : {"NumberOfLines", "NumberOfStrips", "NumberOfPolys"})
        if (const std::string* v = tag->find(cells); v && detail::parse_number<std::uint64_t>(*v, cells) != 0)
          throw Malformed(fmt::format("{} must be 0", cells));
    } else if (name == "FieldData") {
      require_parent({"PolyData", "Piece"});
    } else if (name == "PointData" || name == "Points" || name == "Verts" || name == "CellData" || name == "Lines" ||
               name == "Strips" || name == "Polys") {
      require_parent({"Piece"});
      if (name == "Points") {
        if (seen_points) throw Malformed("more than one <Points>");
        seen_points = true;
      }
    } else if (name == "DataArray") {
      require_parent({"FieldData", "PointData", "Points", "Verts"});
      h.arrays.push_back(parse_data_array(*tag, parent));
    } else if (name == "AppendedData") {
      require_parent({"VTKFile"});
      expect_attribute(*tag, "encoding", "raw");
      if (tag->self_closing) throw Malformed("empty <AppendedData>");
      std::size_t i = scan.position();
      while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\n' || text[i] == '\r')) ++i;
      if (i >= text.size() || text[i] != '_') throw Malformed("no '_' at the start of the appended data");
      h.data_start = i + 1;
      if (!seen_piece) throw Malformed("no <Piece>");
      if (!seen_points) throw Malformed("no <Points>");
      return h;
    } else {
      throw Malformed("unexpected element <" + name + ">");
    }
    if (!tag->self_closing) open.push_back(name);
  }
  throw Malformed("no <AppendedData encoding=\"raw\">");
}

std::string label_of(const ArrayRef& a) { return fmt::format("{} array '{}'", a.section, a.name.substr(0, 40)); }

// The byte count of the block at `a.offset`, checked against the data that are
// really there.
std::size_t block_size(std::string_view data, const ArrayRef& a) {
  std::uint64_t bytes = 0;
  if (a.offset > data.size() || data.size() - a.offset < sizeof bytes)
    throw Malformed(fmt::format("{}: offset {} is past the end of the data", label_of(a), a.offset));
  std::memcpy(&bytes, data.data() + a.offset, sizeof bytes);
  const std::size_t left = data.size() - static_cast<std::size_t>(a.offset) - sizeof bytes;
  if (bytes > left) throw Malformed(fmt::format("{}: {} bytes announced, {} left", label_of(a), bytes, left));
  const std::uint64_t tuple_bytes = type_size(a.type) * static_cast<std::uint64_t>(a.components);
  if (bytes % tuple_bytes != 0)
    throw Malformed(fmt::format("{}: {} bytes are not whole {}-byte tuples", label_of(a), bytes, tuple_bytes));
  if (a.tuples && *a.tuples != bytes / tuple_bytes)
    throw Malformed(
        fmt::format("{}: NumberOfTuples is {}, the data hold {}", label_of(a), *a.tuples, bytes / tuple_bytes));
  return static_cast<std::size_t>(bytes);
}

// Cells are not returned, but a reader that accepted nonsense there would hand
// ParaView a file it cannot draw.
void check_verts(const std::map<std::string, std::vector<std::int64_t>>& verts, const Header& h) {
  if (verts.empty() && h.num_verts == 0) return;
  if (verts.size() != 2) throw Malformed("<Verts> needs both connectivity and offsets");
  const auto& connectivity = verts.at("connectivity");
  const auto& offsets = verts.at("offsets");
  if (offsets.size() != h.num_verts)
    throw Malformed(fmt::format("{} vertex offsets for NumberOfVerts {}", offsets.size(), h.num_verts));
  std::int64_t previous = 0;
  for (std::int64_t o : offsets) {
    if (o < previous) throw Malformed("vertex offsets decrease");
    previous = o;
  }
  if (static_cast<std::uint64_t>(previous) != connectivity.size())
    throw Malformed("vertex offsets do not match the connectivity length");
  for (std::int64_t c : connectivity)
    if (c < 0 || static_cast<std::uint64_t>(c) >= h.num_points) throw Malformed("vertex index out of range");
}

bool is_trailer(std::string_view rest) {
  auto skip_space = [&] {
    while (!rest.empty() && (rest[0] == ' ' || rest[0] == '\t' || rest[0] == '\n' || rest[0] == '\r'))
      rest.remove_prefix(1);
  };
  for (std::string_view tag : {"</AppendedData>", "</VTKFile>"}) {
    skip_space();
    if (!rest.starts_with(tag)) return false;
    rest.remove_prefix(tag.size());
  }
  skip_space();
  return rest.empty();
}

VtpFile parse_vtp(std::string_view text) {
  const Header h = parse_header(text);
  const std::string_view data = text.substr(h.data_start);

  // Blocks that share bytes never come from a writer, and would let a small
  // file make the reader allocate without bound.
  std::vector<std::pair<std::size_t, std::size_t>> extents;  // [begin, end) of each block
  for (const ArrayRef& a : h.arrays)
    extents.emplace_back(a.offset, a.offset + sizeof(std::uint64_t) + block_size(data, a));
  std::vector<std::pair<std::size_t, std::size_t>> sorted = extents;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 1; k < sorted.size(); ++k)
    if (sorted[k].first < sorted[k - 1].second) throw Malformed("two arrays share bytes of the appended data");

  VtpFile file;
  file.num_points = static_cast<std::size_t>(h.num_points);
  bool have_points = false;
  std::map<std::string, std::vector<std::int64_t>> verts;
  for (std::size_t k = 0; k < h.arrays.size(); ++k) {
    const ArrayRef& a = h.arrays[k];
    const std::string label = label_of(a);
    VtpArray arr{a.type, a.components, {}};
    const auto* p = reinterpret_cast<const std::byte*>(data.data());
    arr.bytes.assign(p + extents[k].first + sizeof(std::uint64_t), p + extents[k].second);
    const std::size_t tuples = arr.bytes.size() / (type_size(a.type) * static_cast<std::size_t>(a.components));
    if ((a.section == "PointData" || a.section == "Points") && tuples != h.num_points)
      throw Malformed(fmt::format("{}: {} tuples for {} points", label, tuples, h.num_points));
    if (a.section == "Points") {
      if (have_points) throw Malformed("more than one Points array");
      if (a.components != 3 || (a.type != "Float32" && a.type != "Float64"))
        throw Malformed("Points must be Float32 or Float64 with 3 components");
      have_points = true;
      file.points = std::move(arr);
    } else if (a.section == "Verts") {
      if (a.name != "connectivity" && a.name != "offsets") throw Malformed(label + ": unexpected in <Verts>");
      if (a.components != 1 || a.type != "Int64") throw Malformed(label + ": must be a scalar Int64 array");
      if (!verts.emplace(a.name, arr.values<std::int64_t>()).second) throw Malformed(label + ": duplicate name");
    } else {
      if (a.name.empty()) throw Malformed(fmt::format("{} array without a Name", a.section));
      auto& target = a.section == "PointData" ? file.point_data : file.field_data;
      if (!target.emplace(a.name, std::move(arr)).second) throw Malformed(label + ": duplicate name");
    }
  }
  if (!have_points) throw Malformed("no Points array");
  check_verts(verts, h);
  // The closing tags after the last block are what shows a file was not cut short.
  const std::size_t data_end = sorted.empty() ? 0 : sorted.back().second;
  if (!is_trailer(data.substr(data_end))) throw Malformed("truncated or trailing garbage after the appended data");
  return file;
}

}  // namespace

template <class Real>
void write_vtp(const fs::path& path, const ParticleSet<Real>& particles, double time) {
  const std::size_t n = particles.size();
  const auto fields = particles.fields();
  VtpBuilder b;
  b.line("<?xml version=\"1.0\"?>");
  b.line(R"(<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">)");
  b.line("  <PolyData>");
  b.line("    <FieldData>");
  char* out = b.array<double>("      ", "TimeValue", 1, 1, " NumberOfTuples=\"1\"");
  put(out, time);
  b.line("    </FieldData>");
  b.line(fmt::format(
      R"(    <Piece NumberOfPoints="{0}" NumberOfVerts="{0}" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="0">)",
      n));

  b.line("      <PointData>");
  for (const auto& f : fields)
    if (f.name != "position" && !f.internal) put_field(b, "        ", f, n, f.name);
  for (const auto& f : particles.int_fields())
    if (!f.internal) put_field(b, "        ", f, n, f.name);
  out = b.array<std::uint64_t>("        ", "id", 1, n);
  for (std::size_t i = 0; i < n; ++i) put(out, particles.id[i]);
  b.line("      </PointData>");

  b.line("      <Points>");
  for (const auto& f : fields)
    if (f.name == "position") put_field(b, "        ", f, n, "Points");
  b.line("      </Points>");

  // One vertex cell per particle, so ParaView renders the points as they are.
  b.line("      <Verts>");
  out = b.array<std::int64_t>("        ", "connectivity", 1, n);
  for (std::size_t i = 0; i < n; ++i) put(out, static_cast<std::int64_t>(i));
  out = b.array<std::int64_t>("        ", "offsets", 1, n);
  for (std::size_t i = 0; i < n; ++i) put(out, static_cast<std::int64_t>(i + 1));
  b.line("      </Verts>");
  b.line("    </Piece>");
  b.line("  </PolyData>");
  write_file_atomic(path, std::move(b).finish());
}

template void write_vtp<float>(const fs::path&, const ParticleSet<float>&, double);
template void write_vtp<double>(const fs::path&, const ParticleSet<double>&, double);

VtpFile read_vtp(const fs::path& path) {
  const std::string text = read_regular_file(path, max_particle_file_bytes());
  try {
    return parse_vtp(text);
  } catch (const Malformed& e) {
    throw IoError(fmt::format("{}: {}", path.string(), e.what()));
  }
}

}  // namespace swirl::io
