// ParticleOrder: the one order of the particles in memory, owned by the
// simulation and shared by every solver that wants particles sorted in space.
//
// update() each step (when some solver asks for an order):
//   1. the particles' bounding box (a block-order reduction);
//   2. a key frame: per-axis corner at the box's low corner and one quantum q
//      for all axes, so that key space is a cube of side q·2^21:
//        - with a cell request of length L (a cell grid: SPH), q = L·2^−s with
//          s the largest shift for which the cells covering the box, 2^s quanta
//          each, still fit 2^21 quanta per axis; a cell's key is then the
//          particle key >> 3s (the Morton key of its cell coordinates);
//        - otherwise q = (largest extent)·2^−21 (the gravity tree's cube);
//   3. a key per particle: by default a 63-bit Morton key (21 bits per axis,
//      x lowest: the octree's octant digits) of floor((x − corner)/q) clamped
//      into key space; when only a cell grid asks and it asks for rows
//      (CellOrder::Rows), the row-major index of the particle's cell (x
//      fastest), q = L: the grid then scans 9 ranges of three cells per cell
//      instead of up to 27 (docs/performance/sph-grid.md: 17–22 % faster);
//   4. the shared parallel radix sort (stable: ties keep memory order);
//   5. one parallel reorder of every particle field (reorder_particles.hpp).
// The SPH cell grid and the gravity linear octree are views of the sorted keys
// and of the reordered fields: they sort, reorder and copy nothing themselves.
//
// Skin: a request may allow the order to be kept while no particle moved more
// than keep_within since the last sort (a Verlet skin: the grid's cells are
// h + skin wide and keep_within = skin/2). The positions at the last sort are
// then kept as the internal particle field "order.reference_position" (so they
// travel with every checkpoint and need no state of their own), and the keys
// are those of the reference positions. A request with keep_within = 0 (the
// gravity tree: nodes must bound their particles) sorts every step.
//
// Epoch: a counter that changes whenever the particles' memory order or count
// may have changed (a sort that moved anything, or touch()). A holder of a
// field's memory compares epochs before reading: same epoch, same particles at
// the same indices and the same buffers.
//
// Determinism: every pass runs over fixed blocks; the bounds are a max/min
// (exact); the sort is THE stable order. Order, keys and frame are the same
// for any thread count. Units: the positions' (m for SPH).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "swirl/core/aligned.hpp"
#include "swirl/core/morton.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "swirl/parallel/radix_sort.hpp"
#include "swirl/spatial/cell_order.hpp"
#include "swirl/spatial/reorder_particles.hpp"

namespace swirl::spatial {

// A particle position that is not finite: the order cannot place it. The
// simulation turns it into its blow-up report (it names the particle).
class NonFinitePosition : public std::runtime_error {
 public:
  NonFinitePosition() : std::runtime_error("particle order: a particle position is not finite") {}
};

// What a solver asks of the shared order.
struct OrderRequest {
  bool sorted = false;     // particles sorted along the curve
  double cell_length = 0;  // > 0: the keys resolve cubic cells of at least this side (a cell grid)
  double keep_within = 0;  // the order may be kept while no particle moved more than this (0: sort every step)
  CellOrder curve = CellOrder::Morton;  // Rows: row-major cell keys (a cell grid alone)

  // Several solvers' requests as one: sorted if any asks; the largest cell;
  // the smallest tolerance among those that sort; rows only if all ask for rows.
  static OrderRequest combine(const OrderRequest& a, const OrderRequest& b) {
    if (!a.sorted) return b.sorted ? b : a;
    if (!b.sorted) return a;
    const CellOrder curve = a.curve == CellOrder::Rows && b.curve == CellOrder::Rows ? CellOrder::Rows : CellOrder::Morton;
    return {true, std::max(a.cell_length, b.cell_length), std::min(a.keep_within, b.keep_within), curve};
  }
};

// Where the keys live in space.
struct KeyFrame {
  static constexpr unsigned kBitsPerAxis = 21;
  CellOrder curve = CellOrder::Morton;        // Morton keys, or row-major cell indices
  std::array<double, 3> corner{};             // the low corner of key space
  double quantum = 1;                         // side of the finest key cell (Rows: the cell)
  unsigned cell_shift = 0;                    // Morton with cells: a cell is 2^cell_shift quanta per axis
  std::array<std::uint64_t, 3> cells{1, 1, 1};  // cell requests: cells per axis covering the particles
  unsigned key_bits = 3 * kBitsPerAxis;       // the keys' significant bits

  double root_side() const { return std::ldexp(quantum, static_cast<int>(kBitsPerAxis)); }
  double cell_length() const { return std::ldexp(quantum, static_cast<int>(cell_shift)); }
  // The cell key of a particle key: its Morton prefix, or the key itself (Rows).
  std::uint64_t cell_of(std::uint64_t key) const { return curve == CellOrder::Rows ? key : key >> (3 * cell_shift); }
};

template <class Real>
class ParticleOrder {
 public:
  static constexpr std::string_view kReferenceField = "order.reference_position";

  void set_request(const OrderRequest& request) {
    if (request.sorted && (!(request.cell_length >= 0) || !std::isfinite(request.cell_length) ||
                           !(request.keep_within >= 0) || !std::isfinite(request.keep_within)))
      throw std::invalid_argument("particle order: cell length and tolerance must be finite and >= 0");
    if (request.keep_within > 0 && !(request.cell_length > 0))
      throw std::invalid_argument("particle order: a tolerance needs a cell length");
    request_ = request;
  }
  const OrderRequest& request() const { return request_; }
  bool active() const { return request_.sorted; }

  // Sorts and reorders the particles when the request needs it (see the
  // header). Returns true when it sorted. Throws on a non-finite position
  // when it needs the positions (the guard has caught it before in a run).
  bool update(ParticleSet<Real>& p, std::size_t block_size) {
    if (!active()) return false;
    if (p.size() > 0xffffffffu) throw std::invalid_argument("particle order: more than 2^32 - 1 particles");
    const bool skin = request_.keep_within > 0;
    if (skin && valid_ && keys().size() == p.size() && within_tolerance(p, block_size)) return false;
    const std::size_t n = p.size();
    frame_ = make_frame(bounds_of(p, block_size, p.position.x.data(), p.position.y.data(), p.position.z.data()));
    raw_.resize(n);
    const KeyFrame f = frame_;
    parallel::for_blocks_pinned("order_keys", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
      for (std::size_t i = b; i < e; ++i) raw_[i] = key_of(f, double(x[i]), double(y[i]), double(z[i]));
    });
    sorter_.sort(raw_, frame_.key_bits);
    const auto order = sorter_.order();
    const bool moved = parallel::reduce_blocks_pinned(
        "order_moved", n, block_size, false,
        [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i)
            if (order[i] != i) return true;
          return false;
        },
        [](bool a, bool b) { return a || b; });
    if (moved) {
      reorder_.apply(p, order, block_size);
      ++epoch_;
    }
    keys_view_ = sorter_.keys();  // the sort's own buffer: no copy
    if (skin) remember(p, block_size);
    valid_ = true;
    ++sorts_;
    return true;
  }

  // Restores the order a checkpointed run had, from its reference positions
  // (a skin run) without moving any particle: the next update() decides as the
  // uninterrupted run would have. Without a skin the next update() sorts anyway.
  void resume(ParticleSet<Real>& p, std::size_t block_size) {
    valid_ = false;
    ++epoch_;
    if (!(active() && request_.keep_within > 0)) return;
    const std::size_t ref = p.add_field(std::string(kReferenceField), 3, FieldUse::Internal);
    const Real *x = p.extra(ref, 0).data(), *y = p.extra(ref, 1).data(), *z = p.extra(ref, 2).data();
    const std::size_t n = p.size();
    frame_ = make_frame(bounds_of(p, block_size, x, y, z));
    resumed_keys_.resize(n);
    const KeyFrame f = frame_;
    parallel::for_blocks_pinned("order_keys", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t i = b; i < e; ++i) resumed_keys_[i] = key_of(f, double(x[i]), double(y[i]), double(z[i]));
    });
    // The reference positions of a checkpoint are in sorted order, unless the
    // file is not what it claims: then sort again on the next update().
    keys_view_ = resumed_keys_;
    valid_ = std::is_sorted(resumed_keys_.begin(), resumed_keys_.end());
  }

  // The particles changed count or order outside update() (a new particle, a
  // checkpoint read): the next update() sorts, and the epoch changes.
  void touch() {
    valid_ = false;
    ++epoch_;
  }

  // After update(): the sorted keys, one per particle in storage order, and their frame.
  std::span<const std::uint64_t> keys() const { return keys_view_; }
  const KeyFrame& frame() const { return frame_; }
  bool valid() const { return valid_; }
  std::uint64_t epoch() const { return epoch_; }
  std::uint64_t sorts() const { return sorts_; }
  // True when a cell request could be honoured (the box spans at most 2^21 cells per axis).
  bool cells_fit() const { return cells_fit_; }
  std::size_t bytes() const {
    return (resumed_keys_.capacity() + raw_.capacity()) * sizeof(std::uint64_t) + reorder_.bytes() +
           raw_.size() * 2 * (sizeof(std::uint64_t) + sizeof(std::uint32_t));
  }

  // The key of a point in a frame (the far faces map to the last quantum, or cell).
  static std::uint64_t key_of(const KeyFrame& f, double x, double y, double z) {
    const double inv = 1.0 / f.quantum;
    if (f.curve == CellOrder::Rows) {
      const std::uint64_t cx = std::min(coordinate(x, f.corner[0], inv), f.cells[0] - 1),
                          cy = std::min(coordinate(y, f.corner[1], inv), f.cells[1] - 1),
                          cz = std::min(coordinate(z, f.corner[2], inv), f.cells[2] - 1);
      return (cz * f.cells[1] + cy) * f.cells[0] + cx;
    }
    return morton_key(coordinate(x, f.corner[0], inv), coordinate(y, f.corner[1], inv), coordinate(z, f.corner[2], inv));
  }

 private:
  struct Bounds {
    std::array<double, 3> lo, hi;
  };

  static std::uint64_t coordinate(double x, double corner, double inv_quantum) {
    constexpr double last = double((std::uint64_t{1} << KeyFrame::kBitsPerAxis) - 1);
    const double c = std::floor((x - corner) * inv_quantum);
    return c >= last ? std::uint64_t(last) : (c > 0 ? std::uint64_t(c) : 0);
  }

  static Bounds bounds_of(const ParticleSet<Real>& p, std::size_t block_size, const Real* x, const Real* y,
                          const Real* z) {
    const LocalBounds box = local_bounds(p.size(), block_size, x, y, z);
    if (!box.finite) throw NonFinitePosition();
    return {box.lo, box.hi};
  }

  KeyFrame make_frame(const Bounds& b) { return frame_for(request_, b.lo, b.hi, cells_fit_); }

 public:
  // The bounding box of n positions (exact min and max per axis, in double;
  // zero for none) and whether every coordinate is finite: one vectorised pass
  // over fixed blocks, the same for any thread count. update()'s bounds, and
  // each rank's share of the global box (dist::global_key_frame).
  struct LocalBounds {
    std::array<double, 3> lo, hi;
    bool finite;
  };
  static LocalBounds local_bounds(std::size_t n, std::size_t block_size, const Real* x, const Real* y, const Real* z) {
    using MinMax = std::array<double, 7>;  // lo xyz, hi xyz, and Σ x·0 (NaN iff some x is not finite)
    constexpr double inf = std::numeric_limits<double>::infinity();
    const MinMax init{inf, inf, inf, -inf, -inf, -inf, 0};
    const MinMax box = parallel::reduce_blocks_pinned(
        "order_bounds", n, block_size, init,
        [&](std::size_t b, std::size_t e) {
          MinMax m = init;
          const Real* axes[3] = {x, y, z};
          for (std::size_t a = 0; a < 3; ++a) {
            Real lo = std::numeric_limits<Real>::infinity(), hi = -std::numeric_limits<Real>::infinity(), poison = 0;
            const Real* v = axes[a];
#pragma omp simd reduction(min : lo) reduction(max : hi) reduction(+ : poison)
            for (std::size_t i = b; i < e; ++i) {
              lo = std::min(lo, v[i]);
              hi = std::max(hi, v[i]);
              poison += v[i] * Real(0);
            }
            m[a] = double(lo);
            m[a + 3] = double(hi);
            m[6] += double(poison);
          }
          return m;
        },
        [](MinMax a, const MinMax& b) {
          for (std::size_t k = 0; k < 3; ++k) {
            a[k] = std::min(a[k], b[k]);
            a[k + 3] = std::max(a[k + 3], b[k + 3]);
          }
          a[6] += b[6];
          return a;
        });
    LocalBounds out{};
    out.finite = box[6] == 0;
    for (std::size_t a = 0; a < 3; ++a) {
      out.lo[a] = n == 0 ? 0.0 : box[a];
      out.hi[a] = n == 0 ? 0.0 : box[a + 3];
      out.finite = out.finite && std::isfinite(out.lo[a]) && std::isfinite(out.hi[a]);
    }
    return out;
  }

  // The key frame update() uses for particles whose bounding box is [lo, hi]
  // (per axis, in double) under `request`; cells_fit tells whether a cell
  // request could be honoured. A pure function: a distributed run computes the
  // one-rank frame from the global box (dist/halo.hpp).
  static KeyFrame frame_for(const OrderRequest& request, const std::array<double, 3>& lo,
                            const std::array<double, 3>& hi, bool& cells_fit) {
    KeyFrame f;
    f.corner = lo;
    const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    const double length = request.cell_length;
    cells_fit = true;
    if (length > 0) {
      std::uint64_t widest = 1;
      for (std::size_t a = 0; a < 3; ++a) {
        const double span = (hi[a] - lo[a]) / length;
        if (!(span < double(std::uint64_t{1} << KeyFrame::kBitsPerAxis) - 1)) {
          cells_fit = false;
          break;
        }
        f.cells[a] = static_cast<std::uint64_t>(std::floor(span)) + 1;
        widest = std::max(widest, f.cells[a]);
      }
      if (cells_fit && request.curve == CellOrder::Rows) {
        f.curve = CellOrder::Rows;
        f.quantum = length;
        f.key_bits = std::max(1u, static_cast<unsigned>(std::bit_width(f.cells[0] * f.cells[1] * f.cells[2] - 1)));
        return f;
      }
      if (cells_fit) {
        f.cell_shift = KeyFrame::kBitsPerAxis - static_cast<unsigned>(std::bit_width(widest - 1));
        f.quantum = std::ldexp(length, -static_cast<int>(f.cell_shift));
        return f;
      }
      f.cells = {1, 1, 1};
    }
    f.curve = CellOrder::Morton;
    f.cell_shift = 0;
    f.quantum = extent > 0 ? std::ldexp(extent, -static_cast<int>(KeyFrame::kBitsPerAxis)) : 1.0;
    return f;
  }

 private:
  void remember(ParticleSet<Real>& p, std::size_t block_size) {
    const std::size_t ref = p.add_field(std::string(kReferenceField), 3, FieldUse::Internal);
    parallel::for_blocks_pinned("order_remember", p.size(), block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (int a = 0; a < 3; ++a) std::copy(p.position[a].data() + b, p.position[a].data() + e, p.extra(ref, a).data() + b);
    });
  }

  // True while no particle moved more than keep_within from its reference
  // position (computed in double; a max is exact, so the same for any thread count).
  bool within_tolerance(const ParticleSet<Real>& p, std::size_t block_size) const {
    const std::size_t ref = p.find_field(kReferenceField);
    if (ref == ParticleSet<Real>::npos) return false;
    const Real *rx = p.extra(ref, 0).data(), *ry = p.extra(ref, 1).data(), *rz = p.extra(ref, 2).data();
    const Real *x = p.position.x.data(), *y = p.position.y.data(), *z = p.position.z.data();
    const double worst = parallel::reduce_blocks_pinned(
        "order_displacement", p.size(), block_size, 0.0,
        [&](std::size_t b, std::size_t e) {
          double w = 0;
          for (std::size_t i = b; i < e; ++i) {
            const double dx = double(x[i]) - double(rx[i]), dy = double(y[i]) - double(ry[i]),
                         dz = double(z[i]) - double(rz[i]);
            const double d2 = dx * dx + dy * dy + dz * dz;
            // A non-finite position asks for a sort, whose bounds check reports it.
            w = d2 > w || !(d2 == d2) ? (d2 == d2 ? d2 : std::numeric_limits<double>::infinity()) : w;
          }
          return w;
        },
        [](double a, double b) { return std::max(a, b); });
    const double tol = request_.keep_within;
    return worst <= tol * tol;
  }

  OrderRequest request_;
  KeyFrame frame_;
  bool cells_fit_ = true;
  bool valid_ = false;
  std::uint64_t epoch_ = 0;
  std::uint64_t sorts_ = 0;
  AlignedVector<std::uint64_t> raw_;   // keys in the order before the sort
  std::span<const std::uint64_t> keys_view_;  // sorted keys, aligned with storage: sorter_'s or resumed_keys_
  AlignedVector<std::uint64_t> resumed_keys_;  // the keys resume() rebuilt from the reference positions
  parallel::RadixSort<std::uint64_t> sorter_;
  ParticleReorder<Real> reorder_;
};

// Compiled once, in src/spatial/particle_order.cpp: users link the float and double copies
// instead of compiling them again.
extern template class ParticleOrder<float>;
extern template class ParticleOrder<double>;

}  // namespace swirl::spatial
