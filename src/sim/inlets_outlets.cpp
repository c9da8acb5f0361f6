// The float and double instantiations of swirl/sim/inlets_outlets.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/sim/inlets_outlets.hpp"

namespace swirl::sim {

template class InletsAndOutlets<float>;
template class InletsAndOutlets<double>;

}  // namespace swirl::sim
