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

#include <array>
#include <cstdint>

#include "swirl/core/enum_names.hpp"
#include "swirl/core/morton.hpp"

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

// The names scenes use (sph.grid.cell_order, sph.grid.table).
inline constexpr std::array<EnumName<CellOrder>, 2> kCellOrderNames{{{"rows", CellOrder::Rows}, {"morton", CellOrder::Morton}}};
inline constexpr std::array<EnumName<CellTable>, 3> kCellTableNames{
    {{"auto", CellTable::Auto}, {"dense", CellTable::Dense}, {"hashed", CellTable::Hashed}}};

// The Morton key functions live in core/morton.hpp (shared with the octree).
using swirl::morton_compact;
using swirl::morton_key;
using swirl::morton_spread;

}  // namespace swirl::spatial
