// The float and double instantiations of swirl/sph/sph_fluid.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/sph/sph_fluid.hpp"

namespace swirl::sph {

template class SphFluid<float>;
template class SphFluid<double>;

}  // namespace swirl::sph
