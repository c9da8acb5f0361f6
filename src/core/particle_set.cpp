// The float and double instantiations of swirl/core/particle_set.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/core/particle_set.hpp"

namespace swirl {

template struct Vec3Array<float>;
template struct Vec3Array<double>;
template class ParticleSet<float>;
template class ParticleSet<double>;

}  // namespace swirl
