// The seeds' published figures that `swirl bench` prints beside ours: every
// number is typed here once, with the table or figure (or the sentence of the
// text) it comes from. Nothing else in the code types a seed figure; derived
// values (cost per particle, speedups, efficiencies) are computed from these.
//
// Provenance, as the seeds state it:
//   thesis (seed 000, Hjelte 2006, chapter 5):
//     PPC 970     measured, one core of a 2.0 GHz PowerMac G5, gcc 4.0 -fast;
//     Cell        IBM's Full System Simulator, which models SPE computation
//                 but not DMA memory transfers (section 5.2): not measured.
//   paper (seed 003, Demiroz et al. 2011, section 5):
//     Cell        measured on an IBM QS20 blade (3.2 GHz Cell BE), SDK 3.1 gcc;
//     Xeon        measured, Intel Xeon 3.0 GHz, gcc 3.4.6 -O5.
// Units are in the names (Hz, s, ms, per cent as a fraction of 1 where "share").
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <utility>

namespace swirl::cli::seeds {

// ---- Thesis (seed 000) ---------------------------------------------------

// Table 5.1: update frequency of the scalar implementation on a 2.0 GHz PPC 970
// (measured), for about 15 and about 25 neighbours per particle.
// Table 5.3: update frequency at about 25 neighbours: PPC 970 (the same
// measured column as Table 5.1's), Cell with 1 SPE and with 8 SPEs (simulated).
struct ThesisSphRow {
  std::size_t particles;
  double ppc970_k15_hz;    // Table 5.1
  double ppc970_k25_hz;    // Table 5.1 = Table 5.3 "PPC 970"
  double cell_1spe_hz;     // Table 5.3, simulator
  double cell_8spe_hz;     // Table 5.3, simulator
};
inline constexpr std::array<ThesisSphRow, 9> kThesisSph{{
    {1000, 312.5, 242.4, 168.5, 545.9},
    {2000, 146.2, 118.0, 85.2, 519.2},
    {5000, 54.2, 43.7, 34.6, 252.1},
    {10000, 24.1, 18.9, 17.2, 132.7},
    {15000, 14.0, 11.5, 11.4, 87.2},
    {20000, 9.6, 7.8, 8.5, 66.3},
    {25000, 7.0, 5.9, 6.9, 53.2},
    {30000, 5.5, 4.7, 5.7, 44.5},
    {35000, 4.5, 3.9, 4.9, 38.4},
}};
inline constexpr int kThesisCellSpes = 8;      // Table 5.3, Figure 5.7: the simulator's maximum
inline constexpr int kThesisSettleSteps = 3000;  // chapter 5: steps run "to stabilize" (Figure 5.1)
inline constexpr double kThesisDt = 0.003;       // chapter 5: Δt, s

inline std::optional<ThesisSphRow> thesis_sph_row(std::size_t particles) {
  for (const auto& r : kThesisSph)
    if (r.particles == particles) return r;
  return std::nullopt;
}

// Figure 5.2 (PPC 970, 25 neighbours) is a chart; its text gives: "the SPH
// force calculation subtask use[s] less than 40% of the clock cycles", the
// neighbour search is the most expensive part, integration and collision
// "practically zero". Figure 5.6 (1 SPE): hashing and neighbour search
// "together 80% of total cost".
inline constexpr double kThesisPpcForceShareBelow = 0.40;     // Figure 5.2, text
inline constexpr double kThesisSpeHashSearchShare = 0.80;     // Figure 5.6, text

// Table 5.2: hash table statistics, 15000 particles, about 25 neighbours.
struct ThesisHashStats {
  std::size_t particles = 15000;
  std::size_t buckets = 24001;          // "1.6x number of particles"
  double empty_buckets = 0.89;          // of all buckets
  double colliding_buckets = 0.05;      // of non-empty buckets
  double particles_per_bucket = 5.94;   // in each non-empty bucket
  double redundant_tests = 0.13;        // of all neighbour tests
  double duplicate_interactions = 0.002;  // of all interactions, check off
};
inline constexpr ThesisHashStats kThesisTable52{};
inline constexpr double kThesisTable52Neighbours = 25;

// Section 5.1 (text after Figure 5.3): removing the duplicate check gives "a
// 20%-50% increase in overall performance" on the PPC 970 (measured); section
// 5.2 (end): "approximately 7%" on the Cell (simulated).
inline constexpr double kThesisNoCheckGainPpcLow = 0.20;
inline constexpr double kThesisNoCheckGainPpcHigh = 0.50;
inline constexpr double kThesisNoCheckGainCell = 0.07;

// Section 4.5 ("Bandwidth Requirements"): bytes moved per time step, with N
// particles, M buckets and G neighbours per particle, pass by pass, ending
// "TOTAL: 674N + 8M + 108N²/M + 48NG bytes/timestep. Of these are 452N bytes
// transfered with 128B alignment and 128B or larger transfer sizes."
struct ThesisBandwidthPass {
  const char* pass;
  double per_particle;    // × N
  double per_bucket;      // × M
  double per_n2_over_m;   // × N²/M (particles in the 27 scanned buckets)
  double per_pair;        // × N·G
};
inline constexpr std::array<ThesisBandwidthPass, 8> kThesisBandwidthPasses{{
    {"Hashing", 20, 0, 0, 0},
    {"Building hash table", 46, 8, 0, 0},
    {"Neighbor hashing", 120, 0, 0, 0},
    {"Neighbor searching", 216, 0, 108, 8},
    {"SPH calculations", 64, 0, 0, 40},
    {"Collision handling - pass one", 64, 0, 0, 0},
    {"Time integration", 112, 0, 0, 0},
    {"Collision handling - pass two", 32, 0, 0, 0},
}};
inline constexpr double kThesisBandwidthAlignedPerParticle = 452;  // "452N bytes ... 128B alignment"
// Its example: "50000 particles and a hash table with 75000 buckets, and each
// particle has 30 neighbors on average, and we want to run the simulation at
// 50Hz. The required bandwidth should be roughly 5GB/s (of which 20% are 128B
// sized/aligned)."
inline constexpr std::size_t kThesisBandwidthExampleParticles = 50000;
inline constexpr std::size_t kThesisBandwidthExampleBuckets = 75000;
inline constexpr double kThesisBandwidthExampleNeighbours = 30;
inline constexpr double kThesisBandwidthExampleHz = 50;
inline constexpr double kThesisBandwidthExampleGBs = 5;          // "roughly 5GB/s"
inline constexpr double kThesisBandwidthExampleAligned = 0.20;   // "of which 20% are 128B sized/aligned"
// "For the Cell it is in practice possible to achieve about 15-20GB/s throughput [29]".
inline constexpr double kThesisCellPracticalGBsLow = 15;
inline constexpr double kThesisCellPracticalGBsHigh = 20;

// Bytes per step of the thesis's model (decimal units as the thesis's GB/s).
inline constexpr double thesis_bandwidth_bytes(double n, double m, double g) {
  double bytes = 0;
  for (const auto& p : kThesisBandwidthPasses)
    bytes += p.per_particle * n + p.per_bucket * m + p.per_n2_over_m * n * n / m + p.per_pair * n * g;
  return bytes;
}

// ---- Paper (seed 003) ----------------------------------------------------

// Section 5: defaults of every experiment.
inline constexpr double kPaperOpening = 0.5;  // λ
inline constexpr int kPaperIterations = 50;

// Table 2: execution time in seconds (measured) for 1, 4 and 8 SPEs and the
// compiler flags none, -O1, -O2, -O3. The paper does not say which scheme ran
// it; we infer the enhanced (sub-tree) one: its 1-SPE over 8-SPE -O3 ratios,
// 6.15 at 1024 and 7.33 at 32768, are Figure 10's enhanced S(8) (6.17, 7.32),
// not Figure 9's initial one (3.98, 8.45).
struct PaperTable2Row {
  int spes;
  std::size_t particles;
  double none_s, o1_s, o2_s, o3_s;
};
inline constexpr std::array<PaperTable2Row, 18> kPaperTable2{{
    {1, 1024, 6.70, 4.34, 4.18, 4.18},
    {1, 2048, 17.36, 11.15, 10.74, 10.73},
    {1, 4096, 42.96, 27.47, 26.51, 26.49},
    {1, 8192, 119.03, 73.30, 71.44, 71.41},
    {1, 16384, 347.22, 206.64, 203.05, 202.99},
    {1, 32768, 925.33, 539.51, 533.34, 533.18},
    {4, 1024, 2.04, 1.27, 1.23, 1.23},
    {4, 2048, 5.01, 3.12, 3.01, 3.01},
    {4, 4096, 12.00, 7.45, 7.20, 7.18},
    {4, 8192, 32.03, 19.35, 18.89, 18.85},
    {4, 16384, 91.62, 53.68, 52.79, 52.71},
    {4, 32768, 242.61, 139.65, 138.22, 138.06},
    {8, 1024, 1.18, 0.70, 0.69, 0.68},
    {8, 2048, 2.86, 1.72, 1.66, 1.65},
    {8, 4096, 6.69, 4.02, 3.90, 3.88},
    {8, 8192, 17.19, 10.14, 9.89, 9.86},
    {8, 16384, 49.01, 28.26, 27.82, 27.71},
    {8, 32768, 129.28, 73.71, 72.96, 72.76},
}};

// Table 2, -O3 column, or nothing if the paper has no such row.
inline std::optional<double> paper_table2_o3(int spes, std::size_t particles) {
  for (const auto& r : kPaperTable2)
    if (r.spes == spes && r.particles == particles) return r.o3_s;
  return std::nullopt;
}

// Figures 9 (initial = sub-domain scheme) and 10 (enhanced = sub-tree
// scheme): speedup over 1 SPE; the text gives 1024 and 32768 particles.
struct PaperSpeedupRow {
  bool enhanced;  // false: Figure 9, true: Figure 10
  std::size_t particles;
  double spe2, spe4, spe8;
};
inline constexpr std::array<PaperSpeedupRow, 4> kPaperFig9And10{{
    {false, 1024, 1.61, 2.2, 3.98},
    {true, 1024, 1.93, 3.4, 6.17},
    {false, 32768, 1.95, 4.18, 8.45},
    {true, 32768, 1.98, 3.86, 7.32},
}};

// Figure 11: speedup of 8 SPEs over the Xeon at 4096 particles (text); the
// abstract: "outperform Intel Xeon by a factor of 5.8 and 7.1 for 8192".
struct PaperOverXeon {
  std::size_t particles;
  double initial, enhanced;
  const char* source;
};
inline constexpr std::array<PaperOverXeon, 2> kPaperOverXeon{{
    {4096, 6.22, 7.4, "Fig. 11 text"},
    {8192, 5.8, 7.1, "abstract"},
}};
// Section 5: the enhanced parallelization "resulting in a speedup of 1.4 for
// 32768 particles" over the initial one (8 SPEs, by context).
inline constexpr double kPaperEnhancedOverInitial = 1.4;
inline constexpr std::size_t kPaperEnhancedOverInitialParticles = 32768;
// Section 5: local trees generated per step (sub-domain scheme) for 1024, 8192, 32768 particles.
inline constexpr std::array<std::pair<std::size_t, std::size_t>, 3> kPaperTreesPerStep{{{1024, 8}, {8192, 64}, {32768, 200}}};

// Figures 14 (initial) and 15 (enhanced): speedup of 8 SPEs over the Xeon
// against λ; the text gives only λ = 0.3 at 4096 particles, the best case.
inline constexpr double kPaperFigLambda = 0.3;
inline constexpr std::size_t kPaperFigLambdaParticles = 4096;
inline constexpr double kPaperFig14InitialAtLambda03 = 7.83;
inline constexpr double kPaperFig15EnhancedAtLambda03 = 8.85;

// Table 1: communication and computation times in ms of the enhanced
// parallelization on 8 SPEs, as published (basis not stated: at 4096 its
// total, 221.5 + 17.4 ms, is three times Table 2's 3.88 s / 50 iterations).
// Its rows add up to its totals except at 32768, where the force DMA alone
// (2854.7) exceeds the communication total (2369.0); typed as published.
struct PaperTable1Column {
  std::size_t particles;
  double tree_compute_ms, tree_dma_ms;      // tree construction (SPE)
  double force_compute_ms, force_dma_ms;    // force calculation (SPE)
  double update_compute_ms, update_dma_ms;  // update position (SPE)
  double ppe_compute_ms;                    // PPE-specific: global tree construction
  double sync_force_ms, sync_update_ms;     // synchronisation barriers (SPE)
  double total_compute_ms, total_comm_ms;   // entire application
};
inline constexpr std::array<PaperTable1Column, 6> kPaperTable1{{
    {1024, 1.3, 0.04, 18.3, 0.3, 1.1, 0.05, 2.1, 4.4, 1.7, 22.8, 6.5},
    {2048, 3.2, 0.1, 68.1, 1.2, 2.2, 0.1, 5.2, 13.8, 2.2, 78.8, 17.5},
    {4096, 7.8, 0.2, 198.3, 3.9, 5.4, 0.2, 10.0, 9.7, 3.2, 221.5, 17.4},
    {8192, 22.1, 0.6, 953.6, 22.1, 7.3, 0.3, 21.4, 210.0, 5.1, 1004.5, 238.3},
    {16384, 43.5, 1.1, 3851.5, 94.4, 20.3, 1.2, 46.1, 435.8, 9.7, 3961.6, 542.2},
    {32768, 75.5, 2.1, 11573.9, 2854.7, 41.6, 25.5, 116.8, 2052.7, 26.2, 11807.9, 2369.0},
}};

// Section 5, the text around Table 1 (enhanced parallelization, 8 SPEs),
// shares of the total execution time unless said otherwise.
struct PaperTable1Text {
  double ppe_share_1024 = 0.072, ppe_share_32768 = 0.0084;          // PPE-specific: global tree construction
  double spe_tree_share_1024 = 0.044, spe_tree_share_32768 = 0.0054;  // tree construction on the SPEs
  double update_barrier_share_32768 = 0.001;                         // barrier after the update phase
  double force_barrier_share_32768 = 0.0127;                         // barrier after the force phase
  double force_share_low = 0.883, force_share_high = 0.989;          // of the total computation time
  double communication_over_computation = 0.19;                      // average over the sizes
};
inline constexpr PaperTable1Text kPaperTable1Text{};

inline std::optional<PaperTable1Column> paper_table1(std::size_t particles) {
  for (const auto& c : kPaperTable1)
    if (c.particles == particles) return c;
  return std::nullopt;
}

}  // namespace swirl::cli::seeds
