// The float and double instantiations of swirl/integrate/kick_drift.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/integrate/kick_drift.hpp"

namespace swirl::integrate {

template class KickDriftStepper<float>;
template class KickDriftStepper<double>;

}  // namespace swirl::integrate
