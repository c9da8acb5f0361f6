#include "swirl/io/vtp.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <tuple>

#include "io/io_test_util.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::io {
namespace {

using namespace swirl::io::test;

template <class Real>
class VtpTest : public ::testing::Test {
 protected:
  static constexpr const char* kRealType = sizeof(Real) == 4 ? "Float32" : "Float64";
  TempDir dir;
};
using Reals = ::testing::Types<float, double>;
TYPED_TEST_SUITE(VtpTest, Reals);

// "" if reading `path` throws IoError whose message starts with the path,
// otherwise what happened instead.
std::string read_failure(const fs::path& path) {
  try {
    read_vtp(path);
    return "read succeeded";
  } catch (const IoError& e) {
    if (std::string(e.what()).starts_with(path.string() + ": ")) return "";
    return std::string("message does not start with the path: ") + e.what();
  } catch (const std::exception& e) {
    return std::string("not an IoError: ") + e.what();
  }
}

std::size_t data_start(const std::string& text) {
  const std::size_t tag = text.find("<AppendedData encoding=\"raw\">");
  return tag == std::string::npos ? std::string::npos : text.find('_', tag) + 1;
}

// The DataArray elements of a written file, as attribute maps, in file order.
// (Plain string search: the writer's own layout is known.)
std::vector<std::map<std::string, std::string>> data_arrays(const std::string& text) {
  const std::string header = text.substr(0, data_start(text));
  std::vector<std::map<std::string, std::string>> out;
  for (std::size_t at = 0; (at = header.find("<DataArray ", at)) != std::string::npos;) {
    const std::size_t end = header.find("/>", at);
    auto& attributes = out.emplace_back();
    for (std::size_t eq; (eq = header.find("=\"", at)) < end;) {
      const std::size_t key = header.rfind(' ', eq) + 1, close = header.find('"', eq + 2);
      attributes[header.substr(key, eq - key)] = header.substr(eq + 2, close - eq - 2);
      at = close + 1;
    }
    at = end;
  }
  return out;
}

std::uint64_t u64_at(const std::string& text, std::size_t at) {
  std::uint64_t v = 0;
  std::memcpy(&v, text.data() + at, sizeof v);
  return v;
}

TYPED_TEST(VtpTest, RoundTripsEveryArrayBitExactly) {
  using Real = TypeParam;
  const std::size_t n = 7;
  const auto particles = make_particles<Real>(n);
  const double time = 0.1 + 1.0 / 3.0;
  const auto path = this->dir / "frame.vtp";
  write_vtp(path, particles, time);
  const VtpFile file = read_vtp(path);

  EXPECT_EQ(file.num_points, n);
  const auto fields = particles.fields();
  ASSERT_EQ(fields.front().name, "position");
  EXPECT_EQ(file.points.type, this->kRealType);
  EXPECT_EQ(file.points.components, 3);
  EXPECT_EQ(file.points.bytes, bytes_of(interleaved(fields.front(), n)));

  std::set<std::string> expected_names{"id"}, names;
  for (const auto& f : fields) {
    if (f.name == "position") continue;
    const std::string name(f.name);
    expected_names.insert(name);
    ASSERT_TRUE(file.point_data.count(name)) << name;
    const VtpArray& a = file.point_data.at(name);
    EXPECT_EQ(a.type, this->kRealType) << name;
    EXPECT_EQ(a.components, f.components) << name;
    EXPECT_EQ(a.bytes, bytes_of(interleaved(f, n))) << name;
  }
  for (const auto& f : particles.int_fields()) {
    const std::string name(f.name);
    expected_names.insert(name);
    ASSERT_TRUE(file.point_data.count(name)) << name;
    const VtpArray& a = file.point_data.at(name);
    EXPECT_EQ(a.type, "Int32") << name;
    EXPECT_EQ(a.components, 1) << name;
    EXPECT_EQ(a.values<std::int32_t>(), std::vector<std::int32_t>(f.data[0], f.data[0] + n)) << name;
  }
  for (const auto& [name, a] : file.point_data) names.insert(name);
  EXPECT_EQ(names, expected_names);
  ASSERT_TRUE(file.point_data.count("kind"));
  EXPECT_EQ(file.point_data.at("kind").values<std::int32_t>().front(), std::numeric_limits<std::int32_t>::min());
  ASSERT_TRUE(file.point_data.count("temperature"));
  ASSERT_TRUE(file.point_data.count("vorticity"));
  EXPECT_EQ(file.point_data.at("temperature").components, 1);
  EXPECT_EQ(file.point_data.at("vorticity").components, 3);

  const VtpArray& id = file.point_data.at("id");
  EXPECT_EQ(id.type, "UInt64");
  EXPECT_EQ(id.components, 1);
  EXPECT_EQ(id.values<std::uint64_t>(), std::vector<std::uint64_t>(particles.id.begin(), particles.id.end()));

  ASSERT_EQ(file.field_data.size(), 1u);
  ASSERT_TRUE(file.field_data.count("TimeValue"));
  EXPECT_EQ(file.field_data.at("TimeValue").type, "Float64");
  EXPECT_EQ(file.field_data.at("TimeValue").bytes, bytes_of(std::vector<double>{time}));
}

TYPED_TEST(VtpTest, EmptySetRoundTrips) {
  using Real = TypeParam;
  const auto particles = make_particles<Real>(0);
  const auto path = this->dir / "empty.vtp";
  write_vtp(path, particles, -2.5);
  const VtpFile file = read_vtp(path);

  EXPECT_EQ(file.num_points, 0u);
  EXPECT_EQ(file.points.type, this->kRealType);
  EXPECT_TRUE(file.points.bytes.empty());
  // every real field but position, every integer field, plus id
  EXPECT_EQ(file.point_data.size(), particles.fields().size() + particles.int_fields().size());
  for (const auto& [name, a] : file.point_data) EXPECT_TRUE(a.bytes.empty()) << name;
  ASSERT_TRUE(file.field_data.count("TimeValue"));
  EXPECT_EQ(file.field_data.at("TimeValue").values<double>(), std::vector<double>{-2.5});
}

TYPED_TEST(VtpTest, WritesTheDocumentedLayout) {
  using Real = TypeParam;
  const std::size_t n = 3;
  const auto path = this->dir / "frame.vtp";
  write_vtp(path, make_particles<Real>(n), 1.0);
  const std::string text = slurp(path);

  EXPECT_TRUE(text.starts_with(
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "  <PolyData>\n"
      "    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"appended\" offset=\"0\"/>\n"
      "    </FieldData>\n"
      "    <Piece NumberOfPoints=\"3\" NumberOfVerts=\"3\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      "NumberOfPolys=\"0\">\n"
      "      <PointData>\n"))
      << text.substr(0, 600);
  std::size_t last = 0;
  for (const char* tag : {"<PointData>", "</PointData>", "<Points>", "</Points>", "<Verts>", "</Verts>", "</Piece>",
                          "</PolyData>", "<AppendedData encoding=\"raw\">"}) {
    const std::size_t at = text.find(tag, last);
    ASSERT_NE(at, std::string::npos) << tag;
    last = at;
  }
  EXPECT_TRUE(text.ends_with("\n  </AppendedData>\n</VTKFile>\n"));

  // Every block sits where its offset says, and the blocks tile the data.
  const std::size_t base = data_start(text);
  ASSERT_NE(base, std::string::npos);
  const auto arrays = data_arrays(text);
  const auto written = make_particles<Real>(n);
  ASSERT_EQ(arrays.size(), written.fields().size() + written.int_fields().size() + 4);  // + TimeValue, id, 2 Verts
  std::size_t expected_offset = 0;
  for (const auto& a : arrays) {
    ASSERT_EQ(a.at("format"), "appended");
    const std::size_t offset = std::stoull(a.at("offset"));
    ASSERT_EQ(offset, expected_offset) << a.at("Name");
    const std::uint64_t bytes = u64_at(text, base + offset);
    const std::size_t components = a.count("NumberOfComponents") ? std::stoull(a.at("NumberOfComponents")) : 1;
    const std::size_t tuples = a.at("Name") == "TimeValue" ? 1 : n;
    const std::size_t width = a.at("type") == "Float32" || a.at("type") == "Int32" ? 4 : 8;
    EXPECT_EQ(bytes, tuples * components * width) << a.at("Name");
    if (a.at("Name") == "kind") {
      EXPECT_EQ(a.at("type"), "Int32");
      EXPECT_EQ(a.count("NumberOfComponents"), 0u);
    }
    if (a.at("Name") == "connectivity" || a.at("Name") == "offsets") {
      EXPECT_EQ(a.at("type"), "Int64");
      for (std::size_t i = 0; i < n; ++i)
        EXPECT_EQ(u64_at(text, base + offset + 8 + 8 * i), i + (a.at("Name") == "offsets" ? 1 : 0));
    }
    if (a.at("Name") == "Points") {
      EXPECT_EQ(components, 3u);
    }
    expected_offset = offset + 8 + bytes;
  }
  EXPECT_EQ(base + expected_offset, text.size() - std::string("\n  </AppendedData>\n</VTKFile>\n").size());
}

TYPED_TEST(VtpTest, EscapesFieldNames) {
  using Real = TypeParam;
  auto particles = make_particles<Real>(2);
  const std::string odd = "a<b & \"c\"\td";
  particles.extra(particles.add_field(odd, 1), 0)[1] = Real(42.5);
  const auto path = this->dir / "odd.vtp";
  write_vtp(path, particles, 0.0);
  const VtpFile file = read_vtp(path);
  ASSERT_TRUE(file.point_data.count(odd));
  EXPECT_EQ(file.point_data.at(odd).values<Real>(), (std::vector<Real>{0, Real(42.5)}));
}

// Integer fields: output ones become Int32 arrays placed after the real
// fields, internal ones are not written (as for real fields).
TYPED_TEST(VtpTest, WritesOutputIntegerFieldsOnly) {
  using Real = TypeParam;
  auto particles = make_particles<Real>(3);
  particles.int_field(particles.add_int_field("flag", FieldUse::Internal))[0] = 9;
  particles.int_field(particles.add_int_field("group"))[2] = -4;
  const auto path = this->dir / "ints.vtp";
  write_vtp(path, particles, 0.0);
  const VtpFile file = read_vtp(path);
  EXPECT_FALSE(file.point_data.count("flag"));
  ASSERT_TRUE(file.point_data.count("group"));
  EXPECT_EQ(file.point_data.at("group").type, "Int32");
  EXPECT_EQ(file.point_data.at("group").values<std::int32_t>(), (std::vector<std::int32_t>{0, 0, -4}));
  std::vector<std::string> order;
  for (const auto& a : data_arrays(slurp(path))) order.push_back(a.at("Name"));
  const auto at = [&](const std::string& name) { return std::find(order.begin(), order.end(), name) - order.begin(); };
  EXPECT_LT(at("vorticity"), at("kind"));
  EXPECT_LT(at("kind"), at("group"));
  EXPECT_LT(at("group"), at("id"));
}

TYPED_TEST(VtpTest, RejectsEveryTruncation) {
  const auto full = this->dir / "full.vtp";
  write_vtp(full, make_particles<TypeParam>(3), 1.0);
  const std::string text = slurp(full);
  // Cutting only trailing whitespace leaves a complete file.
  const std::size_t complete = text.find_last_not_of('\n') + 1;
  const auto cut = this->dir / "cut.vtp";
  for (std::size_t len = 0; len < complete; ++len) {
    spit(cut, text.substr(0, len));
    const std::string failure = read_failure(cut);
    ASSERT_EQ(failure, "") << "truncated to " << len << " of " << text.size() << " bytes";
  }
}

// Replaces the value of the k-th occurrence of attribute `key`.
std::string replace_attribute(std::string text, const std::string& key, std::size_t k, const std::string& value) {
  std::size_t at = 0;
  for (std::size_t i = 0; i <= k; ++i) {
    at = text.find(" " + key + "=\"", at);
    if (at == std::string::npos) return text;
    at += key.size() + 3;
  }
  return text.replace(at, text.find('"', at) - at, value);
}

TYPED_TEST(VtpTest, RejectsGarbageOffsets) {
  const auto good = this->dir / "good.vtp";
  write_vtp(good, make_particles<TypeParam>(4), 1.0);
  const std::string text = slurp(good);
  const auto arrays = data_arrays(text);
  const std::size_t data_size = text.size() - data_start(text);
  const auto bad = this->dir / "bad.vtp";
  for (std::size_t k = 0; k < arrays.size(); ++k) {
    for (const std::string& value :
         {std::string("18446744073709551615"), std::string("18446744073709551609"), std::string("99999999999999999999"),
          std::string("-1"), std::string("abc"), std::string(""), std::string("0x10"), std::string("1 "),
          std::to_string(data_size), std::to_string(data_size - 4)}) {
      spit(bad, replace_attribute(text, "offset", k, value));
      EXPECT_EQ(read_failure(bad), "") << "array " << k << " offset=\"" << value << "\"";
    }
  }
  // velocity and acceleration have the same size: sharing one block must not pass.
  ASSERT_EQ(arrays[2].at("Name"), "acceleration");
  spit(bad, replace_attribute(text, "offset", 2, arrays[1].at("offset")));
  EXPECT_EQ(read_failure(bad), "") << "two arrays at one offset";
}

TYPED_TEST(VtpTest, RejectsCorruptByteCounts) {
  const auto good = this->dir / "good.vtp";
  write_vtp(good, make_particles<TypeParam>(4), 1.0);
  const std::string text = slurp(good);
  const std::size_t base = data_start(text);
  const auto bad = this->dir / "bad.vtp";
  for (const auto& a : data_arrays(text)) {
    const std::size_t at = base + std::stoull(a.at("offset"));
    const std::uint64_t count = u64_at(text, at);
    const std::size_t width = a.at("type") == "Float32" || a.at("type") == "Int32" ? 4 : 8;
    for (std::uint64_t wrong : {~std::uint64_t{0}, count + 1, count + 8 * width * 3, count - width * 3,
                                std::uint64_t{1} << 62}) {
      std::string corrupt = text;
      std::memcpy(corrupt.data() + at, &wrong, sizeof wrong);
      spit(bad, corrupt);
      EXPECT_EQ(read_failure(bad), "") << a.at("Name") << " count " << count << " -> " << wrong;
    }
  }
}

TYPED_TEST(VtpTest, RejectsBadVertexCells) {
  const std::size_t n = 4;
  const auto good = this->dir / "good.vtp";
  write_vtp(good, make_particles<TypeParam>(n), 1.0);
  const std::string text = slurp(good);
  const std::size_t base = data_start(text);
  std::map<std::string, std::size_t> values_at;  // where the first value of each Verts array is
  for (const auto& a : data_arrays(text)) values_at[a.at("Name")] = base + std::stoull(a.at("offset")) + 8;
  const auto bad = this->dir / "bad.vtp";
  const std::vector<std::tuple<std::string, std::size_t, std::int64_t>> edits = {
      {"connectivity", 0, -1}, {"connectivity", 3, std::int64_t(n)}, {"offsets", 1, 0}, {"offsets", 3, 5}};
  for (const auto& [name, index, value] : edits) {
    std::string corrupt = text;
    std::memcpy(corrupt.data() + values_at.at(name) + 8 * index, &value, sizeof value);
    spit(bad, corrupt);
    EXPECT_EQ(read_failure(bad), "") << name << "[" << index << "] = " << value;
  }
}

TYPED_TEST(VtpTest, RejectsWrongHeaders) {
  const auto good = this->dir / "good.vtp";
  write_vtp(good, make_particles<TypeParam>(3), 1.0);
  const std::string text = slurp(good);
  const auto bad = this->dir / "bad.vtp";
  const std::vector<std::pair<std::string, std::string>> edits = {
      {"type=\"PolyData\"", "type=\"UnstructuredGrid\""},
      {"header_type=\"UInt64\"", "header_type=\"UInt32\""},
      {" header_type=\"UInt64\"", ""},
      {"byte_order=\"LittleEndian\"", "byte_order=\"BigEndian\""},
      {"format=\"appended\"", "format=\"binary\""},
      {"encoding=\"raw\"", "encoding=\"base64\""},
      {"type=\"UInt64\" Name=\"id\"", "type=\"UInt128\" Name=\"id\""},
      {"type=\"UInt64\" Name=\"id\"", "type=\"Float32\" Name=\"id\""},  // wrong size for the data
      {"NumberOfPoints=\"3\"", "NumberOfPoints=\"4\""},
      {"NumberOfPoints=\"3\"", "NumberOfPoints=\"-3\""},
      {"NumberOfComponents=\"3\"", "NumberOfComponents=\"0\""},
      {"NumberOfComponents=\"3\"", "NumberOfComponents=\"2147483648\""},
      {"NumberOfTuples=\"1\"", "NumberOfTuples=\"2\""},
      {"NumberOfLines=\"0\"", "NumberOfLines=\"1\""},
      {"<AppendedData encoding=\"raw\">\n   _", "<AppendedData encoding=\"raw\">\n   "},
      {"<PointData>", "<PointDat>"},
      {"</Piece>", ""},
      {"<Points>", "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>"},
      {"Name=\"velocity\"", "Name=\"mass\""},
      {"Name=\"offsets\"", "Name=\"offset\""},
      {"Name=\"offsets\"", "Name=\"connectivity\""},
      {"Name=\"velocity\"", "Name=\"velocity\" Name=\"x\""},
      {"Name=\"velocity\"", "Name=\"vel&bogus;\""},
      {"Name=\"velocity\"", "Name=\"vel<ocity\""},
      {"<Verts>", "<Verts><!-- unterminated"},
      {"<?xml", "<!DOCTYPE x><?xml"},
      {"<VTKFile", "<VTKFile x=\"1\"/><VTKFile"},
  };
  for (const auto& [from, to] : edits) {
    std::string edited = text;
    const std::size_t at = edited.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    edited.replace(at, from.size(), to);
    spit(bad, edited);
    EXPECT_EQ(read_failure(bad), "") << from << " -> " << to;
  }
  for (const std::string& junk : {std::string(""), std::string("hello"), std::string("<VTKFile"),
                                  std::string("<VTKFile type=\"PolyData\">"), text.substr(0, data_start(text))}) {
    spit(bad, junk);
    EXPECT_EQ(read_failure(bad), "") << junk.substr(0, 80);
  }
  EXPECT_EQ(read_failure(this->dir / "missing.vtp"), "");
  EXPECT_EQ(read_failure(this->dir.path()), "");  // a directory
}

TYPED_TEST(VtpTest, SurvivesRandomCorruption) {
  const auto good = this->dir / "good.vtp";
  write_vtp(good, make_particles<TypeParam>(5), 1.0);
  const std::string text = slurp(good);
  const auto bad = this->dir / "bad.vtp";
  std::mt19937_64 rng(12345);
  const std::string alphabet = "<>/=\"' _&;#0123456789-xeEaA\n";
  int failures = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::string corrupt = text;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      // Mostly in the XML, where the parser is; sometimes in the binary part.
      const std::size_t limit = rng() % 4 == 0 ? corrupt.size() : data_start(text);
      const std::size_t at = rng() % limit;
      switch (rng() % 3) {
        case 0: corrupt[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: corrupt.erase(at, 1 + rng() % 8); break;
        default: corrupt[at] = static_cast<char>(rng() & 0xff); break;
      }
    }
    spit(bad, corrupt);
    try {
      read_vtp(bad);
    } catch (const IoError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << "trial " << trial << ": " << e.what();
      if (++failures > 5) return;
    }
  }
}

}  // namespace
}  // namespace swirl::io
