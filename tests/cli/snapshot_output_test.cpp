// output.format = "hdf5": Gadget-format snapshots with an XDMF series beside
// them hold the .vtp frames' very values, resume bit-identically, and render.
#include <gtest/gtest.h>

#include <cstring>

#include "cli_support.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/io/vtp.hpp"

namespace {

const std::string kExamples = std::string(SWIRL_SOURCE_DIR) + "/examples/";
const std::string kBoth = " --set 'output.format=[\"vtp\",\"hdf5\"]'";
const std::string kSph = kExamples + "dam_break.toml --set particles.0.spacing=0.03 --set output.interval=0.004" + kBoth;
const std::string kGravity = kExamples + "plummer.toml --set particles.0.count=400 --set output.interval=0.125" + kBoth;

class SnapshotOutput : public Cli {};

// The values of a .vtp array and of the matching snapshot dataset, as doubles.
std::vector<double> vtp_values(const swirl::io::VtpArray& a) {
  if (a.type == "Float32") {
    const auto f = a.values<float>();
    return {f.begin(), f.end()};
  }
  return a.values<double>();
}

void expect_same_frame(const fs::path& vtp_file, const fs::path& h5_file, bool si) {
  const auto vtp = swirl::io::read_vtp(vtp_file);
  const auto h5 = swirl::io::read_snapshot(h5_file);
  ASSERT_EQ(h5.count, vtp.num_points);
  EXPECT_EQ(h5.info.si_units, si);
  EXPECT_EQ(h5.info.time, vtp_values(vtp.field_data.at("TimeValue")).at(0));
  EXPECT_EQ(h5.datasets.at("Coordinates").values, vtp_values(vtp.points));
  EXPECT_EQ(h5.datasets.at("Velocities").values, vtp_values(vtp.point_data.at("velocity")));
  EXPECT_EQ(h5.datasets.at("Masses").values, vtp_values(vtp.point_data.at("mass")));
  const auto ids = vtp.point_data.at("id").values<std::uint64_t>();
  EXPECT_EQ(h5.ids, ids);
  if (si) {
    EXPECT_EQ(h5.datasets.at("Density").values, vtp_values(vtp.point_data.at("density")));
    EXPECT_EQ(h5.info.type, swirl::io::PartType::Gas);
  } else {
    EXPECT_EQ(h5.datasets.at("potential").values, vtp_values(vtp.point_data.at("potential")));
    EXPECT_EQ(h5.info.type, swirl::io::PartType::Collisionless);
  }
}

TEST_F(SnapshotOutput, SnapshotsHoldTheFramesValuesAndTheSeriesListsThem) {
  for (const auto& [scene, si] : {std::pair{kSph, true}, std::pair{kGravity, false}}) {
    const auto out = dir_ / (si ? "sph" : "gravity");
    const auto r = swirl("run " + scene + " --steps 12 --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string xdmf = slurp(out / "particles.xdmf");
    std::size_t frames = 0;
    for (const auto& e : fs::directory_iterator(out)) {
      if (e.path().extension() != ".h5") continue;
      ++frames;
      auto vtp = e.path();
      vtp.replace_extension(".vtp");
      SCOPED_TRACE(e.path().string());
      expect_same_frame(vtp, e.path(), si);
      EXPECT_NE(xdmf.find(e.path().filename().string() + ":/PartType" + (si ? "0" : "1") + "/Coordinates"),
                std::string::npos);
    }
    EXPECT_GE(frames, 2u);
    std::size_t grids = 0;
    for (std::size_t at = xdmf.find("GridType=\"Uniform\""); at != std::string::npos;
         at = xdmf.find("GridType=\"Uniform\"", at + 1))
      ++grids;
    EXPECT_EQ(grids, frames);
  }
}

TEST_F(SnapshotOutput, SnapshotsAndTheirSeriesResumeBitIdentically) {
  ASSERT_EQ(swirl("run " + kSph + " --steps 30 --threads 2 --out " + (dir_ / "a").string()).status, 0);
  ASSERT_EQ(swirl("run " + kSph + " --steps 12 --threads 1 --checkpoint-every-steps 6 --out " + (dir_ / "b").string()).status,
            0);
  const auto r = swirl("run --resume " + (dir_ / "b").string() + " --steps 18 --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_outputs(dir_ / "a", dir_ / "b");  // every .h5, particles.xdmf, the .vtp and the logs
  EXPECT_TRUE(fs::exists(dir_ / "b" / "particles.xdmf"));
}

TEST_F(SnapshotOutput, ARunWithOnlySnapshotsRenders) {
  const auto out = dir_ / "run";
  const auto r = swirl("run " + kExamples + "dam_break.toml --set particles.0.spacing=0.03 --set output.interval=0.004 "
                       "--set 'output.format=\"hdf5\"' --steps 8 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "particles.pvd"));
  const auto render = swirl("render " + out.string() + " --all");
  ASSERT_EQ(render.status, 0) << render.err;
  std::size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(out / "render")) pngs += e.path().extension() == ".png";
  EXPECT_GE(pngs, 2u);
}

}  // namespace
