#include "swirl/io/pvd.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "io/io_test_util.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/vtp.hpp"

namespace swirl::io {
namespace {

using namespace swirl::io::test;

std::vector<std::uint64_t> time_bits(const std::vector<PvdEntry>& entries) {
  std::vector<std::uint64_t> out;
  for (const auto& e : entries) out.push_back(std::bit_cast<std::uint64_t>(e.time));
  return out;
}

std::vector<std::string> file_names(const std::vector<PvdEntry>& entries) {
  std::vector<std::string> out;
  for (const auto& e : entries) out.push_back(e.file);
  return out;
}

class PvdTest : public ::testing::Test {
 protected:
  TempDir dir;
};

TEST_F(PvdTest, ListsEveryFrameWithItsExactTime) {
  const std::vector<double> times = {0.0, 0.1, 1.0 / 3.0, 1e-300, 123456.789, std::nextafter(2.5e10, 3e10), -0.0};
  const auto path = dir / "series.pvd";
  PvdSeries series(path);
  std::vector<PvdEntry> expected;
  for (std::size_t k = 0; k < times.size(); ++k) {
    const std::string file = fmt::format("particles_{:06}.vtp", k);
    series.add(times[k], file);
    expected.push_back({times[k], file});
    const auto read = read_pvd(path);  // the file on disk lists exactly the frames so far
    EXPECT_EQ(time_bits(read), time_bits(expected)) << "after add #" << k;
    EXPECT_EQ(file_names(read), file_names(expected)) << "after add #" << k;
  }
  EXPECT_EQ(time_bits(series.entries()), time_bits(expected));
  EXPECT_EQ(list_dir(dir.path()), std::set<std::string>{"series.pvd"});

  const std::string text = slurp(path);
  EXPECT_TRUE(text.starts_with("<?xml version=\"1.0\"?>\n"
                               "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
                               "  <Collection>\n"
                               "    <DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"particles_000000.vtp\"/>\n"
                               "    <DataSet timestep=\"0.10000000000000001\" group=\"\" part=\"0\" "
                               "file=\"particles_000001.vtp\"/>\n"))
      << text;
  EXPECT_TRUE(text.ends_with("  </Collection>\n</VTKFile>\n"));
}

TEST_F(PvdTest, SetEntriesResumesWithoutWriting) {
  const auto path = dir / "series.pvd";
  PvdSeries series(path);
  series.set_entries({{0.5, "a.vtp"}, {1.5, "b.vtp"}});
  EXPECT_FALSE(fs::exists(path));
  series.add(2.5, "c.vtp");
  EXPECT_EQ(file_names(read_pvd(path)), (std::vector<std::string>{"a.vtp", "b.vtp", "c.vtp"}));
  EXPECT_EQ(time_bits(read_pvd(path)), time_bits({{0.5, ""}, {1.5, ""}, {2.5, ""}}));
}

TEST_F(PvdTest, FileNamesWithMarkupCharactersRoundTrip) {
  const auto path = dir / "series.pvd";
  PvdSeries series(path);
  const std::string odd = "run \"1\" <a&b>/frame's.vtp";
  series.add(1.0, odd);
  EXPECT_EQ(file_names(read_pvd(path)), std::vector<std::string>{odd});
}

TEST_F(PvdTest, FailedAddThrowsAndKeepsEntries) {
  spit(dir / "blocker", "a regular file");
  PvdSeries series(dir / "blocker" / "series.pvd");
  series.set_entries({{1.0, "a.vtp"}});
  EXPECT_THROW(series.add(2.0, "b.vtp"), IoError);
  EXPECT_EQ(series.entries().size(), 1u);
}

// "" if reading `path` throws IoError naming the file, otherwise what happened.
std::string read_failure(const fs::path& path) {
  try {
    read_pvd(path);
    return "read succeeded";
  } catch (const IoError& e) {
    return std::string(e.what()).starts_with(path.string() + ": ") ? "" : std::string("bad message: ") + e.what();
  } catch (const std::exception& e) {
    return std::string("not an IoError: ") + e.what();
  }
}

TEST_F(PvdTest, RejectsMalformedFiles) {
  const auto good = dir / "good.pvd";
  PvdSeries series(good);
  series.add(0.25, "a.vtp");
  series.add(0.5, "b.vtp");
  const std::string text = slurp(good);
  const auto bad = dir / "bad.pvd";

  const std::size_t complete = text.find_last_not_of('\n') + 1;
  for (std::size_t len = 0; len < complete; ++len) {
    spit(bad, text.substr(0, len));
    ASSERT_EQ(read_failure(bad), "") << "truncated to " << len << " bytes";
  }
  const std::vector<std::pair<std::string, std::string>> edits = {
      {"type=\"Collection\"", "type=\"PolyData\""},
      {"timestep=\"0.25\"", "timestep=\"0.25x\""},
      {"timestep=\"0.25\"", "timestep=\"\""},
      {"timestep=\"0.25\"", ""},
      {"file=\"a.vtp\"", "file=\"\""},
      {"file=\"a.vtp\"", "file=\"a.vtp"},
      {"<Collection>", "<Collectio>"},
      {"</Collection>", ""},
      {"<DataSet", "<Foo/><DataSet"},
  };
  for (const auto& [from, to] : edits) {
    std::string edited = text;
    edited.replace(edited.find(from), from.size(), to);
    spit(bad, edited);
    EXPECT_EQ(read_failure(bad), "") << from << " -> " << to;
  }
  EXPECT_EQ(read_failure(dir / "missing.pvd"), "");
}

// A series as the simulation writes it: each frame's TimeValue equals its time
// in the .pvd, for both precisions.
template <class Real>
class PvdSeriesTest : public ::testing::Test {
 protected:
  TempDir dir;
};
using Reals = ::testing::Types<float, double>;
TYPED_TEST_SUITE(PvdSeriesTest, Reals);

TYPED_TEST(PvdSeriesTest, FramesAndCollectionAgree) {
  PvdSeries series(this->dir / "particles.pvd");
  auto particles = make_particles<TypeParam>(4);
  for (int k = 0; k < 4; ++k) {
    const double time = 0.1 * k + 1e-17 * k;
    const std::string file = fmt::format("particles_{:06}.vtp", k);
    particles.mass[0] = TypeParam(k);
    write_vtp(this->dir / file, particles, time);
    series.add(time, file);
  }
  const auto entries = read_pvd(this->dir / "particles.pvd");
  ASSERT_EQ(entries.size(), 4u);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const VtpFile frame = read_vtp(this->dir / entries[k].file);
    EXPECT_EQ(frame.field_data.at("TimeValue").bytes, bytes_of(std::vector<double>{entries[k].time}));
    EXPECT_EQ(frame.point_data.at("mass").template values<TypeParam>()[0], TypeParam(k));
  }
}

}  // namespace
}  // namespace swirl::io
