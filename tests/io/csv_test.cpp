#include "swirl/io/csv.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <charconv>

#include "io/io_test_util.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::io {
namespace {

using namespace swirl::io::test;

template <class Real>
class CsvTest : public ::testing::Test {
 protected:
  TempDir dir;
};
using Reals = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CsvTest, Reals);

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1)
    out.push_back(text.substr(start, nl - start));
  EXPECT_EQ(start, text.size()) << "last line not terminated";
  return out;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t comma; (comma = line.find(',', start)) != std::string::npos; start = comma + 1)
    out.push_back(line.substr(start, comma - start));
  out.push_back(line.substr(start));
  return out;
}

// Parses all of `text`; fails the test otherwise.
template <class T>
T parse(const std::string& text) {
  T value{};
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  EXPECT_TRUE(ec == std::errc{} && end == text.data() + text.size()) << "'" << text << "'";
  return value;
}

TYPED_TEST(CsvTest, HeaderAndRowsParseBackExactly) {
  using Real = TypeParam;
  const std::size_t n = 5;
  const auto particles = make_particles<Real>(n);
  const double time = 2.0 / 3.0;
  const auto path = this->dir / "frame.csv";
  write_csv(path, particles, time);
  const auto lines = lines_of(slurp(path));
  ASSERT_EQ(lines.size(), n + 2);

  ASSERT_TRUE(lines[0].starts_with("# time = ")) << lines[0];
  EXPECT_EQ(std::bit_cast<std::uint64_t>(parse<double>(lines[0].substr(9))), std::bit_cast<std::uint64_t>(time));
  EXPECT_EQ(lines[1],
            "id,x,y,z,velocity_x,velocity_y,velocity_z,acceleration_x,acceleration_y,acceleration_z,"
            "acceleration_prev_x,acceleration_prev_y,acceleration_prev_z,mass,density,pressure,temperature,"
            "vorticity_x,vorticity_y,vorticity_z,kind");

  const auto fields = particles.fields();
  const std::size_t kind = particles.find_int_field("kind");
  for (std::size_t i = 0; i < n; ++i) {
    const auto cells = split(lines[i + 2]);
    ASSERT_EQ(cells.size(), split(lines[1]).size()) << "row " << i;
    EXPECT_EQ(parse<std::uint64_t>(cells[0]), particles.id[i]);
    std::vector<Real> expected, got;
    for (const auto& f : fields)  // position first, as in the columns
      for (int c = 0; c < f.components; ++c) expected.push_back(f.data[c][i]);
    for (std::size_t k = 1; k + 1 < cells.size(); ++k) got.push_back(parse<Real>(cells[k]));
    EXPECT_EQ(bytes_of(got), bytes_of(expected)) << "row " << i << ": " << lines[i + 2];
    EXPECT_EQ(parse<std::int32_t>(cells.back()), particles.int_field(kind)[i]) << "row " << i;
  }
}

TYPED_TEST(CsvTest, EmptySetHasHeaderOnly) {
  const auto path = this->dir / "empty.csv";
  write_csv(path, ParticleSet<TypeParam>(0), 0.0);
  const auto lines = lines_of(slurp(path));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "# time = 0");
  EXPECT_TRUE(lines[1].starts_with("id,x,y,z,velocity_x,")) << lines[1];
}

TYPED_TEST(CsvTest, QuotesFieldNamesWithCommas) {
  auto particles = make_particles<TypeParam>(1);
  particles.add_field("a,\"b\"", 1);
  const auto path = this->dir / "frame.csv";
  write_csv(path, particles, 0.0);
  const auto lines = lines_of(slurp(path));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_TRUE(lines[1].ends_with(",vorticity_z,\"a,\"\"b\"\"\",kind")) << lines[1];
}

// Internal fields, real or integer, are state, not output: no column.
TYPED_TEST(CsvTest, LeavesInternalFieldsOut) {
  auto particles = make_particles<TypeParam>(2);
  particles.add_field("scratch", 1, FieldUse::Internal);
  particles.int_field(particles.add_int_field("flag", FieldUse::Internal))[1] = 5;
  const auto path = this->dir / "frame.csv";
  write_csv(path, particles, 0.0);
  const auto lines = lines_of(slurp(path));
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_TRUE(lines[1].ends_with(",vorticity_z,kind")) << lines[1];
  EXPECT_EQ(split(lines[3]).size(), split(lines[1]).size());
}

TYPED_TEST(CsvTest, WriteFailureThrows) {
  spit(this->dir / "blocker", "x");
  EXPECT_THROW(write_csv(this->dir / "blocker" / "frame.csv", make_particles<TypeParam>(2), 0.0), IoError);
}

}  // namespace
}  // namespace swirl::io
