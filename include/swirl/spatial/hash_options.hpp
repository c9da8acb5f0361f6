// The options of the thesis's spatial hash (spatial_hash.hpp) that replay its
// experiments without changing a result.
//
// DuplicateCheck: hash collisions put particles of other cells into a scanned
// bucket, and the check (is the found particle's cell the searched one?)
// drops them. Ours runs it before the distance test, the thesis's (section
// 4.2.3) after it; both keep exactly the pairs of the brute-force search. Off
// keeps duplicates.
//
// TableBuild: the table (count, prefix sum, scatter) is built on every thread
// (ours) or on one, as the thesis's PPE built it while the SPEs waited
// (section 4.2.3, the serial portion of section 5.1): the same table either way.
//
// NeighbourHashes: the search needs, for every particle, the buckets of the 26
// cells around its own. Ours hashes each of those cells inside the search, as
// it scans it; the thesis precomputes them (section 4.2.3: "These hash values
// are precalculated while the PPE builds the hash table"; section 4.5's
// "Neighbor hashing" pass, N·26·4 bytes written) into a per-particle array
// that the search then reads. The same buckets, so the same pairs in the same
// order either way.
#pragma once

#include <array>

#include "swirl/core/enum_names.hpp"

namespace swirl::spatial {

enum class DuplicateCheck {
  Off,             // every pair within h, duplicates included
  BeforeDistance,  // cell relation first: a colliding entry costs no distance test (ours)
  AfterDistance,   // distance first, then the cell relation of each pair within h (the thesis's)
};

// The names scenes use (sph.hash.check_placement) for the two places of the check.
inline constexpr std::array<EnumName<DuplicateCheck>, 2> kCheckPlacementNames{
    {{"before_distance", DuplicateCheck::BeforeDistance}, {"after_distance", DuplicateCheck::AfterDistance}}};

enum class TableBuild {
  Parallel,  // the counting sort's chunks on every thread (ours)
  Serial,    // one thread, the thesis's PPE
};

// The names scenes use (sph.hash.table_build).
inline constexpr std::array<EnumName<TableBuild>, 2> kTableBuildNames{
    {{"parallel", TableBuild::Parallel}, {"serial", TableBuild::Serial}}};

enum class NeighbourHashes {
  OnTheFly,     // each neighbour cell hashed by the search as it scans it (ours)
  Precomputed,  // 26 hashes per particle written by build(), read by the search (the thesis's)
};

// The names scenes use (sph.hash.neighbour_hashes).
inline constexpr std::array<EnumName<NeighbourHashes>, 2> kNeighbourHashesNames{
    {{"on_the_fly", NeighbourHashes::OnTheFly}, {"precomputed", NeighbourHashes::Precomputed}}};

}  // namespace swirl::spatial
