// The float and double instantiations of swirl/spatial/cell_grid.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/spatial/cell_grid.hpp"

namespace swirl::spatial {

template class SortedCellGrid<float>;
template class SortedCellGrid<double>;

}  // namespace swirl::spatial
