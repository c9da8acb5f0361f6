// The float and double instantiations of swirl/sim/simulation.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/sim/simulation.hpp"

namespace swirl {

template class Simulation<float>;
template class Simulation<double>;

}  // namespace swirl
