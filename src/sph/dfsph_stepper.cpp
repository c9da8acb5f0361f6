// The float and double instantiations of swirl/sph/dfsph_stepper.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/sph/dfsph_stepper.hpp"

namespace swirl::sph {

template class DfsphStepper<float>;
template class DfsphStepper<double>;

}  // namespace swirl::sph
