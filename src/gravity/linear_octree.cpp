// The linear octree: keys, sort, nodes from key prefixes level by level,
// multipoles bottom-up, the per-particle non-recursive walk, and the group
// walk (interaction lists evaluated by interaction_kernels.hpp).
#include "swirl/gravity/linear_octree.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "swirl/core/morton.hpp"
#include "swirl/gravity/interaction_kernels.hpp"
#include "swirl/gravity/pair_law.hpp"
#include "swirl/parallel/for_blocks.hpp"
#include "tree_moments.hpp"

namespace swirl::gravity {

namespace {

// Particles per block of the walk: neighbours along the curve walk similar
// paths, and walks differ in cost, so small blocks balance better.
constexpr std::size_t kWalkBlock = 64;
// Nodes per block of the level-by-level passes.
constexpr std::size_t kNodeBlock = 256;
// The visit stack: each of the ≤ 22 levels leaves at most 7 siblings behind.
constexpr std::size_t kStackDepth = 8 * (LinearOctree<double>::kLevels + 2);


// for_blocks, but a range of one block runs on the calling thread: the top
// levels of the tree have a handful of nodes, and a parallel region per level
// costs more than their work on a loaded machine. The same blocks either way.
template <class Body>
void node_blocks(std::string_view kernel, std::size_t n, Body&& body) {
  if (n <= kNodeBlock) {
    if (n > 0) body(std::size_t(0), n, std::size_t(0));
    return;
  }
  parallel::for_blocks(kernel, n, kNodeBlock, std::forward<Body>(body));
}

template <class Real>
Real to_real_radius2(double r2) {
  constexpr double top = double(std::numeric_limits<Real>::max());
  return Real(r2 < top ? r2 : top);
}

}  // namespace

KeyCube key_cube(const std::array<double, 3>& lo, const std::array<double, 3>& hi, std::size_t count) {
  double side = count ? std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}) : 0.0;
  if (!(side > 0)) side = 1;  // coincident particles (or none): any cube will do
  if (!std::isfinite(side)) throw std::invalid_argument("linear octree: non-finite particle positions");
  KeyCube cube;
  cube.side = side;
  cube.corner = count ? lo : std::array<double, 3>{0, 0, 0};
  return cube;
}

namespace detail {

namespace {

std::array<double, 3> cube_centre(std::uint8_t level, std::uint64_t prefix, const CubeFrame& frame) {
  const double cell = frame.side / double(std::uint64_t(1) << level);
  return {frame.corner[0] + (double(morton_compact(prefix)) + 0.5) * cell,
          frame.corner[1] + (double(morton_compact(prefix >> 1)) + 0.5) * cell,
          frame.corner[2] + (double(morton_compact(prefix >> 2)) + 0.5) * cell};
}

}  // namespace

template <class Real>
NodeMoments leaf_moments(const Real* x, const Real* y, const Real* z, const Real* m, std::uint32_t first,
                         std::uint32_t last, std::uint8_t level, std::uint64_t prefix, const CubeFrame& frame,
                         bool quadrupole) {
  NodeMoments r{};
  for (std::uint32_t s = first; s < last; ++s) {
    r.m += double(m[s]);
    r.x += double(m[s]) * double(x[s]);
    r.y += double(m[s]) * double(y[s]);
    r.z += double(m[s]) * double(z[s]);
  }
  if (last - first == 1) {  // exactly the particle
    r.x = double(x[first]);
    r.y = double(y[first]);
    r.z = double(z[first]);
  } else if (r.m != 0) {
    r.x /= r.m;
    r.y /= r.m;
    r.z /= r.m;
  } else {  // massless: at the cube's centre
    const std::array<double, 3> centre = cube_centre(level, prefix, frame);
    r.x = centre[0];
    r.y = centre[1];
    r.z = centre[2];
  }
  if (quadrupole && last - first > 1) {
    for (std::uint32_t s = first; s < last; ++s) {
      const double dx = double(x[s]) - r.x, dy = double(y[s]) - r.y, dz = double(z[s]) - r.z;
      const double ms = double(m[s]), d2 = dx * dx + dy * dy + dz * dz;
      r.xx += ms * (3 * dx * dx - d2);
      r.xy += ms * 3 * dx * dy;
      r.xz += ms * 3 * dx * dz;
      r.yy += ms * (3 * dy * dy - d2);
      r.yz += ms * 3 * dy * dz;
    }
  }
  return r;
}

NodeMoments parent_moments(const NodeMoments* children, std::size_t count, std::uint8_t level, std::uint64_t prefix,
                           const CubeFrame& frame, bool quadrupole) {
  NodeMoments r{};
  for (std::size_t c = 0; c < count; ++c) {
    r.m += children[c].m;
    r.x += children[c].m * children[c].x;
    r.y += children[c].m * children[c].y;
    r.z += children[c].m * children[c].z;
  }
  if (r.m != 0) {
    r.x /= r.m;
    r.y /= r.m;
    r.z /= r.m;
  } else {
    const std::array<double, 3> centre = cube_centre(level, prefix, frame);
    r.x = centre[0];
    r.y = centre[1];
    r.z = centre[2];
  }
  if (quadrupole) {
    // Parallel-axis theorem: a child's quadrupole about the parent's centre of mass.
    for (std::size_t c = 0; c < count; ++c) {
      const NodeMoments& k = children[c];
      const double dx = k.x - r.x, dy = k.y - r.y, dz = k.z - r.z;
      const double m = k.m, d2 = dx * dx + dy * dy + dz * dz;
      r.xx += k.xx + m * (3 * dx * dx - d2);
      r.xy += k.xy + m * 3 * dx * dy;
      r.xz += k.xz + m * 3 * dx * dz;
      r.yy += k.yy + m * (3 * dy * dy - d2);
      r.yz += k.yz + m * 3 * dy * dz;
    }
  }
  return r;
}

template <class Real>
void store_node(const NodeMoments& r, std::uint8_t level, std::uint64_t prefix, const CubeFrame& frame,
                const LinearTreeSettings& settings, LinearNodes<Real>& t, std::size_t node) {
  t.com_x[node] = Real(r.x);
  t.com_y[node] = Real(r.y);
  t.com_z[node] = Real(r.z);
  t.mass[node] = Real(r.m);
  t.qxx[node] = Real(r.xx);
  t.qxy[node] = Real(r.xy);
  t.qxz[node] = Real(r.xz);
  t.qyy[node] = Real(r.yy);
  t.qyz[node] = Real(r.yz);
  const double opening = settings.opening;
  const double cell = frame.side / double(std::uint64_t(1) << level);
  double radius = std::numeric_limits<double>::infinity();  // λ = 0 or θ = 0: always open
  if (opening > 0) {
    radius = cell / opening;
    if (settings.criterion == Criterion::Barnes) {
      const double dx = frame.corner[0] + (double(morton_compact(prefix)) + 0.5) * cell - r.x;
      const double dy = frame.corner[1] + (double(morton_compact(prefix >> 1)) + 0.5) * cell - r.y;
      const double dz = frame.corner[2] + (double(morton_compact(prefix >> 2)) + 0.5) * cell - r.z;
      radius += std::sqrt(dx * dx + dy * dy + dz * dz);
    }
  }
  t.open2[node] = to_real_radius2<Real>(radius * radius);
}

template NodeMoments leaf_moments<float>(const float*, const float*, const float*, const float*, std::uint32_t,
                                         std::uint32_t, std::uint8_t, std::uint64_t, const CubeFrame&, bool);
template NodeMoments leaf_moments<double>(const double*, const double*, const double*, const double*,
                                          std::uint32_t, std::uint32_t, std::uint8_t, std::uint64_t,
                                          const CubeFrame&, bool);
template void store_node<float>(const NodeMoments&, std::uint8_t, std::uint64_t, const CubeFrame&,
                                const LinearTreeSettings&, LinearNodes<float>&, std::size_t);
template void store_node<double>(const NodeMoments&, std::uint8_t, std::uint64_t, const CubeFrame&,
                                 const LinearTreeSettings&, LinearNodes<double>&, std::size_t);

}  // namespace detail

template <class Real>
void LinearOctree<Real>::check(const ParticleSet<Real>& p, const LinearTreeSettings& settings,
                               std::size_t block_size) const {
  if (block_size == 0) throw std::invalid_argument("linear octree: block size must be at least 1");
  if (settings.bucket_size < 1) throw std::invalid_argument("linear octree: bucket size must be at least 1");
  if (settings.group_size < 1) throw std::invalid_argument("linear octree: group size must be at least 1");
  if (p.size() >= npos) throw std::invalid_argument("linear octree: too many particles for 32-bit indices");
}

template <class Real>
void LinearOctree<Real>::build(const ParticleSet<Real>& p, const LinearTreeSettings& settings, std::size_t block_size) {
  check(p, settings, block_size);
  settings_ = settings;
  block_size_ = block_size;
  assembled_ = false;
  make_keys(p, block_size);
  make_nodes();
  make_multipoles();
  make_groups();
}

template <class Real>
void LinearOctree<Real>::build_sorted(const ParticleSet<Real>& p, std::span<const std::uint64_t> sorted_keys,
                                      const std::array<double, 3>& corner, double side,
                                      const LinearTreeSettings& settings, std::size_t block_size) {
  check(p, settings, block_size);
  if (sorted_keys.size() != p.size()) throw std::invalid_argument("linear octree: one key per particle expected");
  if (!(side > 0) || !std::isfinite(side)) throw std::invalid_argument("linear octree: the key cube's side must be > 0");
  settings_ = settings;
  block_size_ = block_size;
  assembled_ = false;
  corner_ = corner;
  side_ = side;
  keys_ = sorted_keys;
  const std::size_t n = p.size();
  x_ = {p.position.x.data(), n};
  y_ = {p.position.y.data(), n};
  z_ = {p.position.z.data(), n};
  m_ = {p.mass.data(), n};
  order_.resize(n);
  parallel::for_blocks("linear_octree_identity", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t s = b; s < e; ++s) order_[s] = std::uint32_t(s);
  });
  make_nodes();
  make_multipoles();
  make_groups();
}

template <class Real>
void LinearOctree<Real>::make_groups() {
  const LinearNodes<Real>& t = nodes_;
  groups_.clear();
  if (t.size() == 0) return;
  // Depth first, first child first: the groups come out in curve order.
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    if (t.child_count[n] == 0 || t.end[n] - t.begin[n] <= settings_.group_size) {
      groups_.push_back(n);
      continue;
    }
    for (std::uint32_t c = t.first_child[n] + t.child_count[n]; c-- > t.first_child[n];) stack.push_back(c);
  }
}

template <class Real>
void LinearOctree<Real>::make_keys(const ParticleSet<Real>& p, std::size_t block_size) {
  const std::size_t n = p.size();
  // The bounding cube (a reduction in block order: the same for any thread count).
  using Bounds = std::array<double, 6>;  // lo xyz, hi xyz
  constexpr double inf = std::numeric_limits<double>::infinity();
  const Bounds bounds = parallel::reduce_blocks(
      "linear_octree_bounds", n, block_size, Bounds{inf, inf, inf, -inf, -inf, -inf},
      [&](std::size_t b, std::size_t e) {
        Bounds r{inf, inf, inf, -inf, -inf, -inf};
        for (int a = 0; a < 3; ++a) {
          const Real* x = p.position[a].data();
          for (std::size_t i = b; i < e; ++i) {
            r[std::size_t(a)] = std::min(r[std::size_t(a)], double(x[i]));
            r[std::size_t(a) + 3] = std::max(r[std::size_t(a) + 3], double(x[i]));
          }
        }
        return r;
      },
      [](const Bounds& a, const Bounds& b) {
        return Bounds{std::min(a[0], b[0]), std::min(a[1], b[1]), std::min(a[2], b[2]),
                      std::max(a[3], b[3]), std::max(a[4], b[4]), std::max(a[5], b[5])};
      });
  const KeyCube cube = key_cube({bounds[0], bounds[1], bounds[2]}, {bounds[3], bounds[4], bounds[5]}, n);
  side_ = cube.side;
  corner_ = cube.corner;

  const double scale = key_scale(side_);
  raw_keys_.resize(n);
  parallel::for_blocks("linear_octree_keys", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t i = b; i < e; ++i)
      raw_keys_[i] = octree_key(double(p.position.x[i]), double(p.position.y[i]), double(p.position.z[i]), corner_,
                                scale);
  });
  sorter_.sort(raw_keys_, 3 * kLevels);
  keys_ = sorter_.keys();

  const auto order = sorter_.order();
  order_.resize(n);
  own_x_.resize(n);
  own_y_.resize(n);
  own_z_.resize(n);
  own_m_.resize(n);
  parallel::for_blocks("linear_octree_gather", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t s = b; s < e; ++s) {
      const std::uint32_t i = order[s];
      order_[s] = i;
      own_x_[s] = p.position.x[i];
      own_y_[s] = p.position.y[i];
      own_z_[s] = p.position.z[i];
      own_m_[s] = p.mass[i];
    }
  });
  x_ = own_x_;
  y_ = own_y_;
  z_ = own_z_;
  m_ = own_m_;
}

template <class Real>
void LinearOctree<Real>::make_nodes() {
  const std::size_t n = x_.size();
  const std::span<const std::uint64_t> keys = keys_;
  LinearNodes<Real>& t = nodes_;
  auto resize = [&](std::size_t count) {
    t.begin.resize(count);
    t.end.resize(count);
    t.first_child.resize(count);
    t.child_count.resize(count);
    t.level.resize(count);
    t.prefix.resize(count);
  };
  resize(0);
  depth_ = 0;
  if (n == 0) {
    resize(0);
  } else {
    resize(1);
    t.begin[0] = 0;
    t.end[0] = std::uint32_t(n);
    t.level[0] = 0;
    t.prefix[0] = 0;
    t.first_child[0] = npos;
    t.child_count[0] = 0;
  }
  const std::size_t bucket = settings_.bucket_size;
  std::vector<std::array<std::uint32_t, 9>> bounds;
  std::size_t level_begin = 0, level_end = t.size();
  while (level_begin < level_end) {
    const std::size_t count = level_end - level_begin;
    bounds.resize(count);
    // Where each node's octants start in the sorted keys: a node is split
    // when it holds more than a bucket and is not at the finest level.
    node_blocks("linear_octree_split", count, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t node = level_begin + k;
        const std::uint32_t first = t.begin[node], last = t.end[node];
        auto& bound = bounds[k];
        bound.fill(first);
        unsigned children = 0;
        if (last - first > bucket && t.level[node] < kLevels) {
          const unsigned shift = 3u * unsigned(kLevels - 1 - t.level[node]);
          bound[8] = last;
          for (std::uint64_t c = 1; c < 8; ++c)
            bound[c] = std::uint32_t(std::partition_point(keys.begin() + first, keys.begin() + last,
                                                          [&](std::uint64_t key) { return ((key >> shift) & 7u) < c; }) -
                                     keys.begin());
          for (std::size_t c = 0; c < 8; ++c) children += bound[c] < bound[c + 1] ? 1u : 0u;
        }
        t.child_count[node] = std::uint8_t(children);
      }
    });
    // Children of the level, in node order, each node's next to each other.
    std::size_t next = level_end;
    for (std::size_t node = level_begin; node < level_end; ++node) {
      t.first_child[node] = t.child_count[node] ? std::uint32_t(next) : npos;
      next += t.child_count[node];
    }
    if (next >= npos) throw std::invalid_argument("linear octree: too many nodes for 32-bit indices");
    resize(next);
    node_blocks("linear_octree_children", count, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t node = level_begin + k;
        if (!t.child_count[node]) continue;
        std::uint32_t child = t.first_child[node];
        for (std::uint64_t c = 0; c < 8; ++c) {
          if (bounds[k][c] == bounds[k][c + 1]) continue;
          t.begin[child] = bounds[k][c];
          t.end[child] = bounds[k][c + 1];
          t.level[child] = std::uint8_t(t.level[node] + 1);
          t.prefix[child] = (t.prefix[node] << 3) | c;
          t.first_child[child] = npos;
          t.child_count[child] = 0;
          ++child;
        }
      }
    });
    if (next > level_end) depth_ = t.level[level_end];
    level_begin = level_end;
    level_end = next;
  }
}

template <class Real>
void LinearOctree<Real>::make_multipoles() {
  LinearNodes<Real>& t = nodes_;
  const std::size_t count = t.size();
  // Moments in double while they are summed; stored in Real at the end.
  std::vector<detail::NodeMoments> mom(count);
  const detail::CubeFrame frame{corner_, side_};
  // Nodes are stored level by level: find each level's range.
  std::vector<std::size_t> level_start(std::size_t(depth_) + 2, count);
  for (std::size_t node = count; node-- > 0;) level_start[t.level[node]] = node;
  const bool quadrupole = settings_.multipole == Multipole::Quadrupole;
  for (int level = depth_; level >= 0; --level) {
    const std::size_t lb = level_start[std::size_t(level)], le = level_start[std::size_t(level) + 1];
    node_blocks("linear_octree_multipoles", le - lb, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t node = lb + b; node < lb + e; ++node) {
        if (t.child_count[node] == 0)
          mom[node] = detail::leaf_moments(x_.data(), y_.data(), z_.data(),
                                           m_.data(), t.begin[node], t.end[node], t.level[node], t.prefix[node],
                                           frame, quadrupole);
        else
          mom[node] = detail::parent_moments(mom.data() + t.first_child[node], t.child_count[node], t.level[node],
                                             t.prefix[node], frame, quadrupole);
      }
    });
  }

  for (auto* a : {&t.com_x, &t.com_y, &t.com_z, &t.mass, &t.qxx, &t.qxy, &t.qxz, &t.qyy, &t.qyz, &t.open2})
    a->resize(count);
  node_blocks("linear_octree_store", count, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t node = b; node < e; ++node)
      detail::store_node(mom[node], t.level[node], t.prefix[node], frame, settings_, t, node);
  });
}

template <class Real>
void LinearOctree<Real>::assemble(LinearNodes<Real> nodes, std::span<const Real> x, std::span<const Real> y,
                                  std::span<const Real> z, std::span<const Real> m, std::vector<std::uint32_t> groups,
                                  const LinearTreeSettings& settings) {
  if (settings.walk != Walk::Group) throw std::invalid_argument("linear octree: an assembled tree needs the group walk");
  if (settings.group_size < 1 || settings.bucket_size < 1)
    throw std::invalid_argument("linear octree: bucket and group sizes must be at least 1");
  const std::size_t n = x.size();
  if (y.size() != n || z.size() != n || m.size() != n)
    throw std::invalid_argument("linear octree: assemble needs x, y, z and m of one length");
  if (n >= npos) throw std::invalid_argument("linear octree: too many particles for 32-bit indices");
  const std::size_t count = nodes.size();
  for (const auto* a : {&nodes.com_x, &nodes.com_y, &nodes.com_z, &nodes.mass, &nodes.qxx, &nodes.qxy, &nodes.qxz,
                        &nodes.qyy, &nodes.qyz, &nodes.open2})
    if (a->size() != count) throw std::invalid_argument("linear octree: assemble needs every node array full");
  if (nodes.end.size() != count || nodes.first_child.size() != count || nodes.child_count.size() != count)
    throw std::invalid_argument("linear octree: assemble needs every node array full");
  for (std::size_t k = 0; k < count; ++k) {
    if (nodes.begin[k] > nodes.end[k] || nodes.end[k] > n)
      throw std::invalid_argument("linear octree: assemble: a node's range is outside the particles");
    if (nodes.child_count[k] != 0 && (nodes.first_child[k] <= k || nodes.first_child[k] + nodes.child_count[k] > count))
      throw std::invalid_argument("linear octree: assemble: a node's children are outside the nodes");
  }
  for (const std::uint32_t g : groups)
    if (g >= count || nodes.begin[g] == nodes.end[g])
      throw std::invalid_argument("linear octree: assemble: a group is not a node with particles");
  settings_ = settings;
  assembled_ = true;
  nodes_ = std::move(nodes);
  own_x_.assign(x.begin(), x.end());
  own_y_.assign(y.begin(), y.end());
  own_z_.assign(z.begin(), z.end());
  own_m_.assign(m.begin(), m.end());
  x_ = own_x_;
  y_ = own_y_;
  z_ = own_z_;
  m_ = own_m_;
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), std::uint32_t(0));
  keys_ = {};
  raw_keys_.clear();
  corner_ = {0, 0, 0};
  side_ = 0;
  depth_ = 0;
  for (const std::uint8_t l : nodes_.level) depth_ = std::max(depth_, int(l));
  groups_ = std::move(groups);
  schedule_.clear();
  slot_cost_.clear();
  group_counts_.clear();
}

template <class Real>
void LinearOctree<Real>::adopt_curve_order() {
  for (std::size_t s = 0; s < order_.size(); ++s) order_[s] = std::uint32_t(s);
}

template <class Real>
void LinearOctree<Real>::walk_one(std::size_t s, Accumulator<Real>& acc, WalkCounts& counts) const {
  const LinearNodes<Real>& t = nodes_;
  if (t.size() == 0) return;
  const Real tx = x_[s], ty = y_[s], tz = z_[s];
  const Real eps2 = Real(settings_.softening * settings_.softening);
  const bool quadrupole = settings_.multipole == Multipole::Quadrupole;
  const auto slot = std::uint32_t(s);
  std::array<std::uint32_t, kStackDepth> stack;
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t n = stack[--top];
    ++counts.nodes;
    const Real dx = t.com_x[n] - tx, dy = t.com_y[n] - ty, dz = t.com_z[n] - tz;
    const Real r2 = dx * dx + dy * dy + dz * dz;
    const bool holds_target = slot - t.begin[n] < t.end[n] - t.begin[n];  // begin ≤ s < end, unsigned
    if (!holds_target && r2 > t.open2[n]) {
      ++counts.multipoles;
      const Real inv = inverse_distance(r2 + eps2);
      if (quadrupole) {
        const Quadrupole<Real> Q{t.qxx[n], t.qxy[n], t.qxz[n], t.qyy[n], t.qyz[n], -(t.qxx[n] + t.qyy[n])};
        add_cell(dx, dy, dz, t.mass[n], Q, inv, acc);
      } else {
        add_point(dx, dy, dz, t.mass[n], inv, acc);
      }
    } else if (t.child_count[n] == 0) {
      const std::uint32_t first = t.begin[n], last = t.end[n];
      for (std::uint32_t k = first; k < last; ++k) {
        if (k == slot) continue;
        acc.add(x_[k] - tx, y_[k] - ty, z_[k] - tz, m_[k], eps2);
      }
      counts.pairs += last - first - (holds_target ? 1 : 0);
    } else {
      // Reversed, so the first child is visited first.
      for (std::uint32_t c = t.first_child[n] + t.child_count[n]; c-- > t.first_child[n];) stack[top++] = c;
    }
  }
}

template <class Real>
std::uint64_t LinearOctree<Real>::walk_group(std::size_t g, GroupLists& lists) const {
  const LinearNodes<Real>& t = nodes_;
  const std::uint32_t group = groups_[g];
  const std::uint32_t gb = t.begin[group], ge = t.end[group];
  GroupLists& l = lists;
  // The targets: every particle of the group, or its active ones.
  l.targets.clear();
  for (std::uint32_t s = gb; s < ge; ++s)
    if (active_slot_.empty() || active_slot_[s]) l.targets.push_back(s);
  const std::uint32_t first = l.targets.front();
  Real lo[3] = {x_[first], y_[first], z_[first]}, hi[3] = {x_[first], y_[first], z_[first]};
  for (const std::uint32_t s : l.targets) {
    lo[0] = std::min(lo[0], x_[s]);
    lo[1] = std::min(lo[1], y_[s]);
    lo[2] = std::min(lo[2], z_[s]);
    hi[0] = std::max(hi[0], x_[s]);
    hi[1] = std::max(hi[1], y_[s]);
    hi[2] = std::max(hi[2], z_[s]);
  }
  for (auto* a : {&l.px, &l.py, &l.pz, &l.pm, &l.cx, &l.cy, &l.cz, &l.cm, &l.cqxx, &l.cqxy, &l.cqxz, &l.cqyy, &l.cqyz})
    a->clear();
  auto add_particles = [&](std::uint32_t b, std::uint32_t e) {
    l.px.insert(l.px.end(), x_.begin() + b, x_.begin() + e);
    l.py.insert(l.py.end(), y_.begin() + b, y_.begin() + e);
    l.pz.insert(l.pz.end(), z_.begin() + b, z_.begin() + e);
    l.pm.insert(l.pm.end(), m_.begin() + b, m_.begin() + e);
  };
  // The group's own particles first, the targets in their order (self_offset
  // = 0 skips the self pairs), then a partly active group's other particles.
  if (l.targets.size() == std::size_t(ge - gb)) {
    add_particles(gb, ge);
  } else {
    for (const std::uint32_t s : l.targets) add_particles(s, s + 1);
    for (std::uint32_t s = gb; s < ge; ++s)
      if (!active_slot_[s]) add_particles(s, s + 1);
  }
  l.stack.resize(kStackDepth);
  std::uint32_t* stack = l.stack.data();
  std::size_t top = 0;
  std::uint64_t popped = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t n = stack[--top];
    ++popped;
    if (n == group) continue;  // already in the list
    const std::uint32_t nb = t.begin[n], ne = t.end[n];
    bool open = nb <= gb && ge <= ne;  // an ancestor of the group (ranges nest): holds its particles
    if (!open) {
      // Distance from the centre of mass to the box, per axis 0 inside the
      // slab: with the per-particle walk's operations on the nearest coordinate.
      const Real cx = t.com_x[n], cy = t.com_y[n], cz = t.com_z[n];
      const Real ex = std::max(std::max(lo[0] - cx, cx - hi[0]), Real(0));
      const Real ey = std::max(std::max(lo[1] - cy, cy - hi[1]), Real(0));
      const Real ez = std::max(std::max(lo[2] - cz, cz - hi[2]), Real(0));
      const Real d2 = ex * ex + ey * ey + ez * ez;
      if (d2 > t.open2[n]) {
        l.cx.push_back(cx);
        l.cy.push_back(cy);
        l.cz.push_back(cz);
        l.cm.push_back(t.mass[n]);
        l.cqxx.push_back(t.qxx[n]);
        l.cqxy.push_back(t.qxy[n]);
        l.cqxz.push_back(t.qxz[n]);
        l.cqyy.push_back(t.qyy[n]);
        l.cqyz.push_back(t.qyz[n]);
        continue;
      }
      open = t.child_count[n] != 0;
      if (!open) {
        add_particles(nb, ne);
        continue;
      }
    }
    // Reversed, so the first child is visited first.
    for (std::uint32_t c = t.first_child[n] + t.child_count[n]; c-- > t.first_child[n];) stack[top++] = c;
  }
  return popped;
}

template <class Real>
WalkCounts LinearOctree<Real>::evaluate_groups(GravityField<Real>& out) {
  const LinearNodes<Real>& t = nodes_;
  const std::size_t n = x_.size(), groups = groups_.size();
  // Costliest first (dynamic hand-out then balances the tail): the last
  // evaluation's cost per sorted slot summed over the group — after a rebuild
  // an estimate, the curve moving little between steps — or, the first time,
  // the particle count. The order changes only who computes a group, never
  // its result.
  // With an active set: only the groups holding an active particle, each
  // costed by its active slots.
  const bool partial = !active_slot_.empty();
  std::vector<double> cost(groups);
  const bool known = slot_cost_.size() == n;
  schedule_.clear();
  for (std::size_t g = 0; g < groups; ++g) {
    const std::uint32_t b = t.begin[groups_[g]], e = t.end[groups_[g]];
    double c = 0;
    std::size_t active = e - b;
    if (partial) {
      active = 0;
      for (std::uint32_t s = b; s < e; ++s)
        if (active_slot_[s]) ++active, c += known ? slot_cost_[s] : 1.0;
    } else {
      c = known ? std::accumulate(slot_cost_.begin() + b, slot_cost_.begin() + e, 0.0) : double(e - b);
    }
    cost[g] = c;
    if (active > 0) schedule_.push_back(std::uint32_t(g));
  }
  std::sort(schedule_.begin(), schedule_.end(),
            [&](std::uint32_t a, std::uint32_t b) { return cost[a] > cost[b] || (cost[a] == cost[b] && a < b); });

  group_counts_.assign(groups, WalkCounts{});
  lists_.resize(std::size_t(std::max(parallel::thread_count(), 1)));
  const Real eps2 = Real(settings_.softening * settings_.softening);
  const bool quadrupole = settings_.multipole == Multipole::Quadrupole;
  const KernelPath path = settings_.simd_kernels ? KernelPath::Simd : KernelPath::Scalar;
  parallel::for_blocks("linear_octree_group_walk", schedule_.size(), 1, [&](std::size_t k, std::size_t, std::size_t) {
    const std::size_t g = schedule_[k];
    const auto thread = std::size_t(parallel::thread_index());
    if (thread >= lists_.size()) throw std::logic_error("linear octree: more threads than list buffers");
    GroupLists& l = lists_[thread];
    const std::uint64_t popped = walk_group(g, l);
    const std::uint32_t first = t.begin[groups_[g]];
    const std::size_t count = l.targets.size();
    const Real *tx = x_.data() + first, *ty = y_.data() + first, *tz = z_.data() + first;
    if (count < std::size_t(t.end[groups_[g]] - first)) {  // partly active: the targets' own copies
      l.tx.resize(count), l.ty.resize(count), l.tz.resize(count);
      for (std::size_t k2 = 0; k2 < count; ++k2)
        l.tx[k2] = x_[l.targets[k2]], l.ty[k2] = y_[l.targets[k2]], l.tz[k2] = z_[l.targets[k2]];
      tx = l.tx.data(), ty = l.ty.data(), tz = l.tz.data();
    }
    for (auto* a : {&l.ax, &l.ay, &l.az, &l.phi}) a->assign(count, Real(0));
    const Targets<Real> targets{tx, ty, tz, l.ax.data(), l.ay.data(), l.az.data(), l.phi.data(), count};
    SourceParticles<Real> particles{l.px.data(), l.py.data(), l.pz.data(), l.pm.data(), l.px.size()};
    particles.self_offset = 0;
    add_particle_field(particles, targets, eps2, path);
    if (!l.cx.empty()) {
      const SourceCells<Real> cells{l.cx.data(),   l.cy.data(),   l.cz.data(),   l.cm.data(),   l.cqxx.data(),
                                    l.cqxy.data(), l.cqxz.data(), l.cqyy.data(), l.cqyz.data(), l.cx.size()};
      add_cell_field(cells, targets, eps2, quadrupole, path);
    }
    for (std::size_t k2 = 0; k2 < count; ++k2) {
      const std::uint32_t i = order_[l.targets[k2]];
      out.acceleration.x[i] = l.ax[k2];
      out.acceleration.y[i] = l.ay[k2];
      out.acceleration.z[i] = l.az[k2];
      out.potential[i] = l.phi[k2];
    }
    group_counts_[g] = WalkCounts{popped, std::uint64_t(count) * l.cx.size(),
                                  std::uint64_t(count) * (l.px.size() - 1)};
  });

  WalkCounts total;
  for (const WalkCounts& c : group_counts_) {
    total.nodes += c.nodes;
    total.multipoles += c.multipoles;
    total.pairs += c.pairs;
  }
  if (partial) return total;  // the costs per slot are those of full evaluations
  slot_cost_.resize(n);
  const double cell_flops = quadrupole ? kQuadrupoleFlops : kMonopoleFlops;
  for (std::size_t g = 0; g < groups; ++g) {
    const WalkCounts& c = group_counts_[g];
    // In flops of the kernels, plus a guess of ~20 per node visited.
    const std::uint32_t b = t.begin[groups_[g]], e = t.end[groups_[g]];
    const double group_cost = double(c.pairs) * kParticleFlops + double(c.multipoles) * cell_flops + 20.0 * double(c.nodes);
    std::fill(slot_cost_.begin() + b, slot_cost_.begin() + e, group_cost / double(e - b));
  }
  return total;
}

template <class Real>
void LinearOctree<Real>::add_walk_costs(std::span<std::uint64_t> out) const {
  if (out.size() != x_.size() || group_counts_.size() != groups_.size() || !active_slot_.empty())
    throw std::logic_error("linear octree: walk costs need the last evaluation to be a full group walk");
  const LinearNodes<Real>& t = nodes_;
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const std::uint32_t b = t.begin[groups_[g]], e = t.end[groups_[g]];
    const WalkCounts& c = group_counts_[g];  // count × list length each
    const std::uint64_t per_particle = (c.multipoles + c.pairs) / std::uint64_t(e - b);
    for (std::uint32_t s = b; s < e; ++s) out[order_[s]] += per_particle;
  }
}

template <class Real>
WalkCounts LinearOctree<Real>::evaluate(GravityField<Real>& out, std::size_t block_size, const ActiveSet& active) {
  const std::size_t n = x_.size();
  out.resize(n);
  active_slot_.clear();
  if (!active.all()) {
    active_slot_.resize(n);
    parallel::for_blocks("linear_octree_active", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t s = b; s < e; ++s) active_slot_[s] = active.contains(order_[s]) ? 1 : 0;
    });
  }
  if (settings_.walk == Walk::Group) return evaluate_groups(out);
  return evaluate_particles(out, block_size);
}

template <class Real>
WalkCounts LinearOctree<Real>::evaluate_particles(GravityField<Real>& out, std::size_t block_size) const {
  const std::size_t n = x_.size();
  out.resize(n);
  return parallel::reduce_blocks(
      "linear_octree_walk", n, std::min(block_size, kWalkBlock), WalkCounts{},
      [&](std::size_t b, std::size_t e) {
        WalkCounts counts;
        for (std::size_t s = b; s < e; ++s) {
          if (!active_slot_.empty() && !active_slot_[s]) continue;
          Accumulator<Real> acc;
          walk_one(s, acc, counts);
          const std::uint32_t i = order_[s];
          out.acceleration.x[i] = acc.ax;
          out.acceleration.y[i] = acc.ay;
          out.acceleration.z[i] = acc.az;
          out.potential[i] = acc.phi;
        }
        return counts;
      },
      [](WalkCounts a, const WalkCounts& b) {
        a.nodes += b.nodes;
        a.multipoles += b.multipoles;
        a.pairs += b.pairs;
        return a;
      });
}

template <class Real>
std::size_t LinearOctree<Real>::leaf_count() const {
  return std::size_t(std::count(nodes_.child_count.begin(), nodes_.child_count.end(), std::uint8_t(0)));
}

template <class Real>
std::size_t LinearOctree<Real>::bytes() const {
  const LinearNodes<Real>& t = nodes_;
  std::size_t b = 0;
  for (const auto* a : {&t.com_x, &t.com_y, &t.com_z, &t.mass, &t.qxx, &t.qxy, &t.qxz, &t.qyy, &t.qyz, &t.open2})
    b += a->capacity() * sizeof(Real);
  b += (t.begin.capacity() + t.end.capacity() + t.first_child.capacity()) * sizeof(std::uint32_t);
  b += t.child_count.capacity() + t.level.capacity() + t.prefix.capacity() * sizeof(std::uint64_t);
  b += (own_x_.capacity() + own_y_.capacity() + own_z_.capacity() + own_m_.capacity()) * sizeof(Real);
  b += order_.capacity() * sizeof(std::uint32_t) + raw_keys_.capacity() * sizeof(std::uint64_t);
  b += (groups_.capacity() + schedule_.capacity()) * sizeof(std::uint32_t) + slot_cost_.capacity() * sizeof(double);
  b += group_counts_.capacity() * sizeof(WalkCounts);
  // The own sort's key and order arrays, each with its spare (radix_sort.hpp).
  if (!own_x_.empty()) b += x_.size() * 2 * (sizeof(std::uint64_t) + sizeof(std::uint32_t));
  return b;
}

template class LinearOctree<float>;
template class LinearOctree<double>;

}  // namespace swirl::gravity
