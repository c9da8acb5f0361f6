// The float and double instantiations of swirl/spatial/spatial_hash.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/spatial/spatial_hash.hpp"

namespace swirl::spatial {

template class SpatialHash<float>;
template class SpatialHash<double>;

}  // namespace swirl::spatial
