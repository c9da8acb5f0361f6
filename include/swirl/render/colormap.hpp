// Colour maps: a value t in [0, 1] to a colour, by linear interpolation between
// evenly spaced stops (stop k sits at t = k / (stops − 1)). Values outside
// [0, 1] are clamped, NaN maps to t = 0.
//
// Viridis (SPH quantities) and inferno (log surface density of gravity runs)
// are perceptually uniform maps designed by van der Walt and Smith for
// matplotlib; the stops here are samples of their published colour values.
#pragma once

#include <span>
#include <string_view>

#include "swirl/render/image.hpp"

namespace swirl::render {

enum class ColorMap { Viridis, Inferno };

// The stops of a map, from t = 0 to t = 1.
std::span<const Color> colormap_stops(ColorMap map);

// The colour of t (clamped to [0, 1]).
Color colormap(ColorMap map, double t);

// "viridis" or "inferno".
std::string_view colormap_name(ColorMap map);

}  // namespace swirl::render
