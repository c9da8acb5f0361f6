#include "swirl/dist/halo.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "swirl/core/morton.hpp"
#include "swirl/dist/key_order.hpp"

namespace swirl::dist {

namespace {

// The cells around `cell` (itself included) clipped to the frame, as the
// corners of their box: [lo, hi] per axis.
struct NeighbourBox {
  std::uint64_t lo[3], hi[3];
};

std::uint64_t cell_key(const spatial::KeyFrame& f, std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  return f.curve == spatial::CellOrder::Rows ? (z * f.cells[1] + y) * f.cells[0] + x : morton_key(x, y, z);
}

NeighbourBox neighbour_box(const spatial::KeyFrame& f, std::uint64_t cell) {
  std::uint64_t c[3];
  if (f.curve == spatial::CellOrder::Rows) {
    c[0] = cell % f.cells[0];
    c[1] = (cell / f.cells[0]) % f.cells[1];
    c[2] = cell / f.cells[0] / f.cells[1];
  } else {
    c[0] = morton_compact(cell);
    c[1] = morton_compact(cell >> 1);
    c[2] = morton_compact(cell >> 2);
  }
  NeighbourBox box{};
  for (std::size_t a = 0; a < 3; ++a) {
    box.lo[a] = c[a] > 0 ? c[a] - 1 : 0;
    box.hi[a] = std::min(c[a] + 1, std::uint64_t{f.cells[a]} - 1);
  }
  return box;
}

// Calls visit(cell key) for the cells of box: the 27 (fewer at the frame's
// faces) SortedCellGrid scans around the box's centre cell, as its
// row_ranges() and morton_ranges() loops do.
template <class Visit>
void for_each_cell_in(const spatial::KeyFrame& f, const NeighbourBox& box, Visit&& visit) {
  for (std::uint64_t z = box.lo[2]; z <= box.hi[2]; ++z)
    for (std::uint64_t y = box.lo[1]; y <= box.hi[1]; ++y)
      for (std::uint64_t x = box.lo[0]; x <= box.hi[0]; ++x) visit(cell_key(f, x, y, z));
}

}  // namespace

Traffic Halo::traffic_of(const std::vector<Bytes>& send, int self) {
  Traffic t;
  for (std::size_t d = 0; d < send.size(); ++d) {
    if (static_cast<int>(d) == self || send[d].empty()) continue;
    t.bytes_sent += send[d].size();
    ++t.messages;
  }
  return t;
}

Halo Halo::find(const Communicator& comm, const spatial::KeyFrame& frame, std::span<const std::uint64_t> keys,
                std::uint64_t first_global_index, std::uint64_t global_count, std::span<const std::uint64_t> cut_keys,
                std::size_t tail) {
  const auto ranks = static_cast<std::size_t>(comm.size());
  if (cut_keys.size() + 1 != ranks) throw std::invalid_argument("halo: size()-1 cut keys are needed");
  if (!std::is_sorted(keys.begin(), keys.end())) throw std::invalid_argument("halo: the keys must be sorted");
  if (keys.size() > 0xffffffffu) throw std::invalid_argument("halo: more than 2^32 - 1 particles on one rank");
  Halo h;
  h.rank_ = comm.rank();
  h.first_ = first_global_index;
  h.owned_count_ = keys.size();
  h.owned_ = {0, static_cast<std::uint32_t>(keys.size())};
  h.send_.assign(ranks, {});
  h.recv_count_.assign(ranks, 0);

  // A cell's particle keys: [cell << shift, cell << shift | low) (Rows: the cell key itself).
  const unsigned shift = frame.curve == spatial::CellOrder::Rows ? 0u : 3u * frame.cell_shift;
  const std::uint64_t low = shift == 0 ? 0 : (std::uint64_t{1} << shift) - 1;

  // The cells this rank needs from each other rank: around each of its
  // occupied cells. Both curves' keys grow with each coordinate, so the keys
  // of a cell's neighbours lie between its neighbour box's corner keys: when
  // both corners' particle keys are in this rank's key range, so is every
  // neighbour, and the cell needs nothing (most cells: only those near the
  // range's ends, in space, are scanned one neighbour at a time).
  const std::uint64_t own_lo = h.rank_ > 0 ? cut_keys[static_cast<std::size_t>(h.rank_) - 1] : 0;
  const bool own_hi_bounded = static_cast<std::size_t>(h.rank_) + 1 < ranks;
  const std::uint64_t own_hi = own_hi_bounded ? cut_keys[static_cast<std::size_t>(h.rank_)] : 0;
  std::vector<std::vector<std::uint64_t>> want(ranks);
  // Row-major keys: a neighbour's key differs from the cell's by at most one
  // layer and one row and one cell, so only the keys within that reach of the
  // range's ends can need ghosts: the keys [0, low_end) and [high_begin, n)
  // are scanned, the middle skipped. (Morton keys have no such bound: every
  // cell is looked at, most of them by its corners alone.)
  std::size_t low_end = keys.size(), high_begin = keys.size();
  if (frame.curve == spatial::CellOrder::Rows) {
    const std::uint64_t reach = frame.cells[0] * frame.cells[1] + frame.cells[0] + 1;
    const auto first_at = [&](std::uint64_t key) {
      return static_cast<std::size_t>(std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
    };
    // Cells below own_lo + reach may need a lower rank's; at or above own_hi − reach, a higher one's.
    low_end = h.rank_ == 0 ? 0 : first_at(own_lo > ~std::uint64_t{0} - reach ? ~std::uint64_t{0} : own_lo + reach);
    high_begin = std::max(low_end, own_hi_bounded ? first_at(own_hi < reach ? 0 : own_hi - reach) : keys.size());
  }
  bool any = false;
  std::uint64_t previous = 0;
  const auto look_at = [&](std::uint64_t key) {
    const std::uint64_t cell = frame.cell_of(key);
    if (any && cell == previous) return;
    any = true;
    previous = cell;
    const NeighbourBox box = neighbour_box(frame, cell);
    const std::uint64_t first_key = cell_key(frame, box.lo[0], box.lo[1], box.lo[2]) << shift;
    const std::uint64_t last_key = (cell_key(frame, box.hi[0], box.hi[1], box.hi[2]) << shift) | low;
    if (first_key >= own_lo && (!own_hi_bounded || last_key < own_hi)) return;
    for_each_cell_in(frame, box, [&](std::uint64_t near) {
      const std::uint64_t lo = near << shift, hi = lo | low;
      const int from = owner_of(lo, cut_keys), to = owner_of(hi, cut_keys);
      for (int o = from; o <= to; ++o)
        if (o != h.rank_) want[static_cast<std::size_t>(o)].push_back(near);
    });
  };
  for (std::size_t i = 0; i < low_end; ++i) look_at(keys[i]);
  for (std::size_t i = high_begin; i < keys.size(); ++i) look_at(keys[i]);
  std::vector<Bytes> requests(ranks);
  for (std::size_t o = 0; o < ranks; ++o) {
    std::sort(want[o].begin(), want[o].end());
    want[o].erase(std::unique(want[o].begin(), want[o].end()), want[o].end());
    requests[o] = to_bytes(std::span<const std::uint64_t>(want[o]));
  }
  h.request_traffic_ = traffic_of(requests, h.rank_);
  const std::vector<Bytes> asked = comm.all_to_all(requests);

  // The global last `tail` particles that this rank owns go to every other rank.
  const std::uint64_t tail_from = global_count > tail ? global_count - tail : 0;
  const std::uint64_t own_end = first_global_index + keys.size();
  const std::size_t tail_begin =
      static_cast<std::size_t>(std::clamp(tail_from, first_global_index, own_end) - first_global_index);

  for (std::size_t s = 0; s < ranks; ++s) {
    if (static_cast<int>(s) == h.rank_) continue;
    std::vector<std::uint32_t>& out = h.send_[s];
    // Cells come sorted, so their particles come in increasing memory order.
    std::vector<std::uint64_t> cells;
    append_values(asked[s], cells, "halo: a cell request");
    for (const std::uint64_t cell : cells) {
      const std::uint64_t lo = cell << shift, hi = lo | low;
      const auto b = std::lower_bound(keys.begin(), keys.end(), lo);
      const auto e = std::upper_bound(b, keys.end(), hi);
      for (auto it = b; it != e; ++it) out.push_back(static_cast<std::uint32_t>(it - keys.begin()));
    }
    if (tail_begin < keys.size()) {
      const std::size_t cells_end = out.size();
      for (std::size_t i = tail_begin; i < keys.size(); ++i) out.push_back(static_cast<std::uint32_t>(i));
      std::inplace_merge(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(cells_end), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    }
  }
  return h;
}

}  // namespace swirl::dist
