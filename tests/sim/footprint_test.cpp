// The memory a scene needs, per rank (sim/footprint.hpp): what the one-rank
// estimate counts, how it splits over ranks, and the refusals it makes.
#include "swirl/sim/footprint.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "swirl/scene/load.hpp"

namespace swirl::sim {
namespace {

std::string fmt_gb(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", bytes / 1e9);
  return text;
}

scene::Scene random_box(std::size_t particles) {
  const std::string toml = "particles = " + std::to_string(particles) +
                           "\n[random_box]\nneighbours = 25\n[simulation]\nprecision = \"float\"\ndt = 0.003\n"
                           "steps = 10\n[sph]\nsmoothing_length = 0.05\n";
  return scene::parse_scene(toml, "box.toml");
}

scene::Scene plummer(std::size_t stars) {
  const std::string toml = "[[particles]]\nkind = \"plummer\"\ncount = " + std::to_string(stars) +
                           "\n[nbody]\nsoftening = 0.01\n[simulation]\ndt = 0.01\nsteps = 10\n";
  return scene::parse_scene(toml, "plummer.toml");
}

TEST(Footprint, OneRankCountsFieldsBuildingCopyAndNeighbourLists) {
  const scene::Scene s = random_box(1'000'000);
  const Footprint f = footprint(s);
  ASSERT_EQ(f.memory.size(), 1u);
  // Float: 16 reals and an id (72 B), the scene's double copy (56 B), sorted
  // copies (40 B) and 2 × 40 neighbours × (index, r²) (640 B): 808 B a
  // particle, plus one start per cell key of the dense table.
  EXPECT_GE(f.memory[0], 808e6);
  EXPECT_LT(f.memory[0], 808e6 * 1.5);
  EXPECT_DOUBLE_EQ(f.frame, 1e6 * (72 + 16) + 4096);
}

TEST(Footprint, RanksShareTheParticlesAndRankZeroHoldsTheWholeSetBesides) {
  for (const scene::Scene& s : {random_box(4'000'000), plummer(4'000'000)}) {
    const double one = footprint(s).memory[0];
    const Footprint four = footprint(s, 4);
    ASSERT_EQ(four.memory.size(), 4u);
    EXPECT_EQ(four.memory[1], four.memory[3]);
    // Each rank holds a quarter and its ghosts or imported tree: more than a
    // quarter of the one-rank need, far less than all of it.
    EXPECT_GT(four.memory[1], 0.25 * one * 0.8) << s.file;
    EXPECT_LT(four.memory[1], 0.6 * one) << s.file;
    // Rank 0 builds and gathers the whole set: its fields (and the double copy) once more.
    EXPECT_GT(four.memory[0], four.memory[1] + 4e6 * (16 * 8 + 8)) << s.file;
  }
  // More ranks, less each (ghosts and all).
  const scene::Scene s = random_box(4'000'000);
  EXPECT_LT(footprint(s, 8).memory[1], footprint(s, 4).memory[1]);
}

TEST(Footprint, OneRankIsRefusedAgainstWhatTheMachineHasFree) {
  const scene::Scene s = random_box(1'000'000);
  const double need = footprint(s).memory[0];
  EXPECT_EQ(memory_refusal(s, {{"a", std::uint64_t(need * 2)}}), "");
  const std::string no = memory_refusal(s, {{"a", std::uint64_t(need)}});
  EXPECT_NE(no.find("box.toml: 1000000 particles need about"), std::string::npos) << no;
  EXPECT_NE(no.find("GB of memory, more than the"), std::string::npos) << no;
}

TEST(Footprint, RanksAreCountedAgainstTheHostTheyShare) {
  const scene::Scene s = random_box(4'000'000);
  const Footprint f = footprint(s, 4);
  const double rank0 = f.memory[0], other = f.memory[1];
  const auto bytes = [](double b) { return static_cast<std::uint64_t>(b); };
  // Four hosts, each with room for its rank: fits, though no host could hold the one-rank run.
  const double room = rank0 / 0.85;
  ASSERT_LT(room, footprint(s).memory[0] / 0.9);
  EXPECT_EQ(memory_refusal(s, {{"a", bytes(room)}, {"b", bytes(room)}, {"c", bytes(room)}, {"d", bytes(room)}}), "");
  // Two hosts of two ranks each with the same room: host a (ranks 0 and 1) is short.
  const std::string no =
      memory_refusal(s, {{"a", bytes(room)}, {"a", bytes(room)}, {"b", bytes(room)}, {"b", bytes(room)}});
  EXPECT_NE(no.find("box.toml: 4000000 particles on 4 MPI ranks need about"), std::string::npos) << no;
  EXPECT_NE(no.find(fmt_gb(other) + " GB of memory on each rank and " + fmt_gb(rank0) + " GB on rank 0"),
            std::string::npos)
      << no;
  EXPECT_NE(no.find("GB on host a for its 2 ranks"), std::string::npos) << no;
  // The least free memory a host's ranks saw is the one counted.
  EXPECT_NE(memory_refusal(s, {{"a", bytes(room * 3)}, {"b", bytes(room * 3)}, {"b", bytes(room)},
                               {"b", bytes(room * 3)}}),
            "");
  // Unknown free memory (0) is not checked.
  EXPECT_EQ(memory_refusal(s, {{"a", 0}, {"a", 0}, {"a", 0}, {"a", 0}}), "");
}

}  // namespace
}  // namespace swirl::sim
