// The float and double instantiations of swirl/spatial/particle_order.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/spatial/particle_order.hpp"

namespace swirl::spatial {

template class ParticleOrder<float>;
template class ParticleOrder<double>;

}  // namespace swirl::spatial
