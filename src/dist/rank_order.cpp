// The float and double instantiations of swirl/dist/rank_order.hpp, which declares them
// extern: they are compiled here once, not in every file that uses them.
#include "swirl/dist/rank_order.hpp"

namespace swirl::dist {

template class RankOrder<float>;
template class RankOrder<double>;

}  // namespace swirl::dist
