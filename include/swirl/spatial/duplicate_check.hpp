// Where the spatial hash's duplicate check runs (spatial_hash.hpp): hash
// collisions put particles of other cells into a scanned bucket, and the check
// (is the found particle's cell the searched one?) drops them. Ours runs it
// before the distance test, the thesis's (section 4.2.3) after it; both keep
// exactly the pairs of the brute-force search. Off keeps duplicates.
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

}  // namespace swirl::spatial
