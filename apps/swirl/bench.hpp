// `swirl bench`: options and the two benchmarks.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace swirl::cli {

struct BenchArgs {
  std::vector<std::size_t> particles{10000, 35000};  // SPH
  std::vector<double> neighbours{15, 25};            // SPH target k
  std::vector<int> threads{1, 2};
  int steps = 50;    // SPH timed steps
  int warmup = 10;   // SPH steps before timing
  std::vector<std::size_t> gravity_particles{1024, 2048, 4096, 8192, 16384, 32768};
  std::vector<std::string> schemes{"subdomain", "subtree", "global"};
  int iterations = 50;  // gravity
  double opening = 0.5;
};

int bench_sph_table(const BenchArgs& args);
int bench_gravity_table(const BenchArgs& args);

}  // namespace swirl::cli
