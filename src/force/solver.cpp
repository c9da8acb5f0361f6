// The float and double instantiations of swirl/force/solver.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/force/solver.hpp"

namespace swirl {

template class Solver<float>;
template class Solver<double>;

}  // namespace swirl
