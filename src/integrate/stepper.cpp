// The float and double instantiations of swirl/integrate/stepper.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/integrate/stepper.hpp"

namespace swirl::integrate {

template class Stepper<float>;
template class Stepper<double>;

}  // namespace swirl::integrate
