// The thesis's hash-table statistics (Table 5.2), computed from an actual
// table and an actual search: `swirl hash-stats` prints them.
#pragma once

#include <cstddef>
#include <cstdint>

#include "swirl/core/particle_set.hpp"
#include "swirl/spatial/spatial_hash.hpp"

namespace swirl::spatial {

struct HashStatistics {
  std::size_t particles = 0;
  std::uint32_t buckets = 0;                   // table size M
  std::uint64_t empty_buckets = 0;
  std::uint64_t buckets_with_collisions = 0;   // non-empty buckets holding particles of ≥ 2 cells
  std::uint64_t tests = 0;                     // candidate pairs examined (check on or off: the same)
  std::uint64_t redundant_tests = 0;           // of which the candidate's cell is not the searched cell
  std::uint64_t interactions = 0;              // with the duplicate check on (= the true pairs)
  std::uint64_t interactions_unchecked = 0;    // with the check off
  std::uint64_t duplicate_interactions = 0;    // interactions_unchecked − interactions

  std::uint64_t nonempty_buckets() const { return buckets - empty_buckets; }
  double empty_fraction() const { return buckets ? double(empty_buckets) / double(buckets) : 0.0; }
  double collision_fraction() const {  // of non-empty buckets
    return nonempty_buckets() ? double(buckets_with_collisions) / double(nonempty_buckets()) : 0.0;
  }
  double particles_per_nonempty_bucket() const {
    return nonempty_buckets() ? double(particles) / double(nonempty_buckets()) : 0.0;
  }
  double redundant_test_fraction() const { return tests ? double(redundant_tests) / double(tests) : 0.0; }
  double duplicate_fraction() const {  // of all interactions found with the check off
    return interactions_unchecked ? double(duplicate_interactions) / double(interactions_unchecked) : 0.0;
  }
  double mean_neighbours() const { return particles ? double(interactions) / double(particles) : 0.0; }
};

// Builds a table of `buckets` buckets with cell length h for the particles and
// searches it with the duplicate check on and off.
template <class Real>
HashStatistics hash_statistics(const ParticleSet<Real>& p, Real h, std::uint32_t buckets, std::size_t block_size) {
  SpatialHash<Real> hash;
  hash.build(p, h, buckets, block_size);
  HashStatistics s;
  s.particles = p.size();
  s.buckets = buckets;
  const auto& offsets = hash.offsets();
  const auto& order = hash.order();
  const auto& cells = hash.cells();
  for (std::uint32_t b = 0; b < buckets; ++b) {
    if (offsets[b] == offsets[b + 1]) {
      ++s.empty_buckets;
      continue;
    }
    const Cell first = cells[order[offsets[b]]];
    for (std::uint32_t slot = offsets[b] + 1; slot < offsets[b + 1]; ++slot) {
      if (!(cells[order[slot]] == first)) {
        ++s.buckets_with_collisions;
        break;
      }
    }
  }
  NeighbourList<Real> lists;
  auto ignore = [](std::uint32_t, const std::uint32_t*, const Real*, std::size_t) {};
  SearchCounters checked, unchecked;
  hash.find_neighbours(p, DuplicateCheck::BeforeDistance, block_size, lists, ignore, &checked);
  hash.find_neighbours(p, DuplicateCheck::Off, block_size, lists, ignore, &unchecked);
  s.tests = checked.tests;
  s.redundant_tests = checked.redundant_tests;
  s.interactions = checked.interactions;
  s.interactions_unchecked = unchecked.interactions;
  s.duplicate_interactions = unchecked.interactions - checked.interactions;
  return s;
}

}  // namespace swirl::spatial
