// Timing the paper's experiment (section 5): a Plummer sphere of N particles,
// `iterations` steps of force evaluation + leapfrog update, per phase: the
// rows of the paper's Table 1 (tree construction, force calculation, update
// positions) and the totals of its Table 2; and the accuracy side of its
// Figures 14-15: the force error of the tree against the direct sum for a
// given opening criterion λ.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swirl/gravity/settings.hpp"

namespace swirl::gravity {

// How the scheme splits the work: ours (the defaults) or the paper's
// (settings.hpp: SubdomainSplit, SubtreeSplit, UpperNodes).
struct SplitRules {
  SubdomainSplit subdomain = SubdomainSplit::Adaptive;
  SubtreeSplit subtree = SubtreeSplit::Units;
  UpperNodes upper_nodes = UpperNodes::Opened;
};

struct BenchSettings {
  Scheme scheme = Scheme::Global;
  SplitRules splits{};
  Method method = Method::BarnesHut;
  std::size_t n = 4096;
  double opening = 0.5;          // λ (the paper's default)
  int iterations = 50;           // the paper's default
  int threads = 1;
  double softening = 0.01;
  double dt = 1.0 / 128;
  std::uint64_t seed = 1;
  bool single_precision = false;  // float instead of double
};

struct BenchResult {
  // Seconds summed over the iterations (the initial force evaluation excluded).
  double tree_build = 0;  // sorting, tree construction, cutting into units
  double force = 0;       // walks and per-particle sums
  double update = 0;      // drift and kick
  double total = 0;       // whole steps, wall clock
  double mean_nodes_visited = 0;  // per particle, last evaluation
  std::size_t trees = 0;          // trees or units walked, last evaluation
  std::size_t nodes = 0;          // nodes built, last evaluation
};

// Runs the experiment; restores the thread count afterwards. Throws
// std::invalid_argument for bad settings.
BenchResult time_iterations(const BenchSettings& settings);

// The paper's experiment: λ, N, iterations and threads as given, in double.
inline BenchResult time_iterations(Scheme scheme, std::size_t n, double opening, int iterations, int threads) {
  BenchSettings s;
  s.scheme = scheme;
  s.n = n;
  s.opening = opening;
  s.iterations = iterations;
  s.threads = threads;
  return time_iterations(s);
}

// One tree configuration whose force error force_errors() measures.
struct ForceErrorCase {
  Scheme scheme = Scheme::Global;
  double opening = 0.5;  // λ
  SplitRules splits{};
};

// Relative force error e_i = |a_tree,i − a_direct,i| / |a_direct,i| over all
// particles (dimensionless), and the walk's cost.
struct ForceError {
  double median = 0;              // lower median of e_i
  double p99 = 0;                 // 99th percentile of e_i (nearest rank)
  double max = 0;                 // largest e_i
  double mean_nodes_visited = 0;  // per particle, this evaluation
};

// The error of one tree evaluation of `settings`' initial Plummer sphere (its
// n, seed, softening, precision and threads; iterations ignored) for each
// case, against the direct sum in double computed once for all cases. The
// differences are taken in double. Restores the thread count. Throws
// std::invalid_argument for bad settings or cases.
std::vector<ForceError> force_errors(const BenchSettings& settings, const std::vector<ForceErrorCase>& cases);

// The median, 99th percentile (nearest rank) and maximum of `errors`, which it
// sorts; all zero for an empty vector. Shared with the tests' slow twin.
ForceError summarize_errors(std::vector<double>& errors);

}  // namespace swirl::gravity
