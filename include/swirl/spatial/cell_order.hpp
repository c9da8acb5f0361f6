// CellOrder: the order in which SortedCellGrid (spatial/cell_grid.hpp) lays
// out its cells, i.e. how a cell's integer coordinates (cx, cy, cz) become the
// key the particles are sorted by.
//
//  - Rows:   key = (cz·ny + cy)·nx + cx (x fastest). The three cells x−1..x+1
//            of a row are adjacent keys, so the 27 cells around a cell are 9
//            contiguous ranges; rows of one plane are nx keys apart.
//  - Morton: the bits of cx, cy, cz interleaved (Z-order: bit k of cx is key
//            bit 3k, of cy 3k + 1, of cz 3k + 2). Nearby cells are nearby in
//            memory in all three axes, but each of the 27 cells is its own range
//            (merged where they happen to be contiguous). The key space is
//            2^(3·b) for b bits per axis: up to 8× the number of cells.
//
// Coordinates are below 2^21 (a Morton key then fits 63 bits).
//
// CellTable: how the grid finds a cell's particles from its key — a dense
// table over the whole key space, or a hash table of the occupied cells only
// (spatial/occupied_cell_table.hpp) for particles spread over a huge region.
#pragma once

#include <cstdint>

namespace swirl::spatial {

enum class CellOrder {
  Rows,    // row-major, 9 ranges per cell
  Morton,  // Z-order, up to 27 ranges per cell
};

enum class CellTable {
  Auto,    // dense while the key space is at most 4·n + 4096, else hashed
  Dense,   // always dense (an error beyond 2^31 keys)
  Hashed,  // always the hash table of occupied cells
};

// The 21 low bits of v spread to every third bit (bit k → bit 3k).
constexpr std::uint64_t morton_spread(std::uint64_t v) {
  v &= 0x1fffffu;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

// The inverse of morton_spread: bits 0, 3, 6, ... of v packed into 21 bits.
constexpr std::uint64_t morton_compact(std::uint64_t v) {
  v &= 0x1249249249249249ULL;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ULL;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00fULL;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffULL;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffULL;
  v = (v ^ (v >> 32)) & 0x1fffffULL;
  return v;
}

constexpr std::uint64_t morton_key(std::uint64_t cx, std::uint64_t cy, std::uint64_t cz) {
  return morton_spread(cx) | morton_spread(cy) << 1 | morton_spread(cz) << 2;
}

static_assert(morton_key(1, 0, 0) == 1 && morton_key(0, 1, 0) == 2 && morton_key(0, 0, 1) == 4);
static_assert(morton_compact(morton_spread(0x1abcdeu)) == 0x1abcdeu);

}  // namespace swirl::spatial
