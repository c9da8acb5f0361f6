// A run that starts from a snapshot (kind = "snapshot"): the last frame of a
// run comes back bit for bit as a new scene's particles, and a run from a
// relative `file` resumes from another working directory byte-identical to the
// uninterrupted run, with a clear refusal when the file is gone.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <set>

#include "cli_support.hpp"
#include "swirl/io/snapshot.hpp"
#include "swirl/scene/initial_conditions.hpp"
#include "swirl/scene/load.hpp"

namespace {

const std::string kPlummer = std::string(SWIRL_SOURCE_DIR) +
                             "/examples/plummer.toml --set particles.0.count=300 --set output.interval=0.0625 "
                             "--set 'output.format=\"hdf5\"'";

// An N-body scene of one snapshot source; `file` as written in the scene.
std::string from_snapshot(const std::string& file) {
  return R"([simulation]
dt = 0.015625
steps = 12
[nbody]
opening = 0.5
softening = 0.01
[output]
interval = 0.03125
[[particles]]
kind = "snapshot"
file = ")" + file + "\"\n";
}

// The newest .h5 frame of a run folder (frame names count up, zero-padded).
fs::path last_frame(const fs::path& run) {
  std::set<fs::path> frames;
  for (const auto& e : fs::directory_iterator(run))
    if (e.path().extension() == ".h5") frames.insert(e.path());
  EXPECT_GE(frames.size(), 2u) << run;
  return frames.empty() ? fs::path() : *frames.rbegin();
}

// The bits of a double, so that −0 and 0 differ.
std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }

class SnapshotIcs : public Cli {};

TEST_F(SnapshotIcs, ARunsLastFrameStartsANewSceneBitForBit) {
  for (const std::string precision : {"double", "float"}) {
    SCOPED_TRACE(precision);
    const auto run = dir_ / ("run_" + precision);
    const auto r = swirl("run " + kPlummer + " --set 'simulation.precision=\"" + precision + "\"' --steps 8 --out " +
                         run.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const fs::path frame = last_frame(run);
    const auto h5 = swirl::io::read_snapshot(frame);
    ASSERT_EQ(h5.count, 300u);
    const auto scene_file = write_scene("next_" + precision + ".toml",
                                        from_snapshot("run_" + precision + "/" + frame.filename().string()));
    const auto scene = swirl::scene::load_scene(
        scene_file, std::vector<std::string>{"simulation.precision=\"" + precision + "\""});
    const auto check = [&](const auto& p) {
      ASSERT_EQ(p.size(), h5.count);
      const auto& x = h5.datasets.at("Coordinates").values;
      const auto& v = h5.datasets.at("Velocities").values;
      const auto& m = h5.datasets.at("Masses").values;
      for (std::size_t i = 0; i < p.size(); ++i) {
        for (std::size_t axis = 0; axis < 3; ++axis) {
          ASSERT_EQ(bits(double(p.position[int(axis)][i])), bits(x[3 * i + axis])) << i;
          ASSERT_EQ(bits(double(p.velocity[int(axis)][i])), bits(v[3 * i + axis])) << i;
        }
        ASSERT_EQ(bits(double(p.mass[i])), bits(m[i])) << i;
      }
    };
    if (precision == "float") check(swirl::scene::make_particles<float>(scene));
    else check(swirl::scene::make_particles<double>(scene));
    // And the CLI runs it, from the scene's own folder or not.
    const auto next = swirl("run " + scene_file.string() + " --set 'simulation.precision=\"" + precision +
                            "\"' --steps 2 --out " + (dir_ / ("next_run_" + precision)).string());
    EXPECT_EQ(next.status, 0) << next.err;
  }
}

TEST_F(SnapshotIcs, ARunFromARelativeFileResumesFromAnotherFolderByteIdentical) {
  // The initial conditions: a Plummer sphere's last frame, in ics/.
  const auto ics_run = swirl("run " + kPlummer + " --steps 4 --out " + (dir_ / "ics_run").string());
  ASSERT_EQ(ics_run.status, 0) << ics_run.err;
  fs::create_directories(dir_ / "ics");
  fs::copy_file(last_frame(dir_ / "ics_run"), dir_ / "ics" / "start.h5");
  fs::create_directories(dir_ / "scenes");
  fs::create_directories(dir_ / "elsewhere");
  write_scene("scenes/from_ics.toml", from_snapshot("../ics/start.h5"));

  // Both invoked from folders where "../ics/start.h5" names nothing: the path
  // is the scene file's, not the working directory's.
  const std::string in_dir = "cd " + dir_.string() + " && ";
  const std::string in_elsewhere = "cd " + (dir_ / "elsewhere").string() + " && ";
  const auto whole = swirl("run scenes/from_ics.toml --threads 2 --out " + (dir_ / "whole").string(), in_dir);
  ASSERT_EQ(whole.status, 0) << whole.err;
  const auto part = swirl("run scenes/from_ics.toml --steps 5 --threads 1 --checkpoint-every-steps 5 --out " +
                              (dir_ / "part").string(),
                          in_dir);
  ASSERT_EQ(part.status, 0) << part.err;
  const std::string saved = slurp(dir_ / "part" / "scene.toml");
  EXPECT_NE(saved.find((dir_ / "ics" / "start.h5").string()), std::string::npos) << saved;
  const auto resumed = swirl("run --resume " + (dir_ / "part").string() + " --steps 7 --threads 2", in_elsewhere);
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  expect_same_outputs(dir_ / "whole", dir_ / "part");

  // A resume rebuilds the scene from the file before the checkpoint replaces
  // its particles: without the file it is refused, saying what it needs.
  fs::rename(dir_ / "ics" / "start.h5", dir_ / "ics" / "moved.h5");
  const auto gone = swirl("run --resume " + (dir_ / "part").string() + " --steps 2", in_elsewhere);
  EXPECT_EQ(gone.status, 2);
  EXPECT_NE(gone.err.find((dir_ / "part" / "scene.toml").string() + ": particles[0].file: " +
                          (dir_ / "ics" / "start.h5").string() + ": no such file"),
            std::string::npos)
      << gone.err;
  EXPECT_NE(gone.err.find("`swirl run --resume` included"), std::string::npos) << gone.err;
  EXPECT_NE(gone.err.find("put the file back at this path"), std::string::npos) << gone.err;
}

}  // namespace
