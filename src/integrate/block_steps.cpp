// The float and double instantiations of swirl/integrate/block_steps.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/integrate/block_steps.hpp"

namespace swirl::integrate {

template class BlockStepper<float>;
template class BlockStepper<double>;

}  // namespace swirl::integrate
