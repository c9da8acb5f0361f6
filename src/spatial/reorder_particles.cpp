// The float and double instantiations of swirl/spatial/reorder_particles.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/spatial/reorder_particles.hpp"

namespace swirl::spatial {

template class ParticleReorder<float>;
template class ParticleReorder<double>;

}  // namespace swirl::spatial
