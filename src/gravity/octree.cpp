// Octree construction by one-by-one insertion (the paper's Fig. 1), then the
// depth-first renumbering the walk and section 4.2's split rely on.
#include "swirl/gravity/octree.hpp"

#include <algorithm>
#include <limits>

namespace swirl::gravity {

namespace {
template <class Cell>
int octant(const Cell& c, const std::array<double, 4>& x) {
  return (x[0] >= c.cx ? 1 : 0) | (x[1] >= c.cy ? 2 : 0) | (x[2] >= c.cz ? 4 : 0);
}
}  // namespace

template <class Real>
void Octree<Real>::build(const ParticleSet<Real>& p, std::span<const std::uint32_t> members) {
  cells_.clear();
  slot_.resize(members.size());
  next_.assign(members.size(), npos);
  depth_ = 0;
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::array<double, 3> lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  for (std::size_t s = 0; s < members.size(); ++s) {
    const std::uint32_t j = members[s];
    slot_[s] = {double(p.position.x[j]), double(p.position.y[j]), double(p.position.z[j]), double(p.mass[j])};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], slot_[s][a]);
      hi[a] = std::max(hi[a], slot_[s][a]);
    }
  }
  if (!members.empty()) {
    // Root: the members' bounding cube. Coincident members have none; any cube will do.
    double half = 0.5 * std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    if (!(half > 0)) half = 1;
    Cell root{};
    root.cx = 0.5 * (lo[0] + hi[0]);
    root.cy = 0.5 * (lo[1] + hi[1]);
    root.cz = 0.5 * (lo[2] + hi[2]);
    root.half = half;
    root.child.fill(-1);
    root.head = root.tail = npos;
    cells_.push_back(root);
    for (std::uint32_t s = 0; s < members.size(); ++s) insert(s);
  }
  renumber(p, members);
}

template <class Real>
void Octree<Real>::add_leaf(std::uint32_t parent, std::uint32_t slot) {
  const Cell& up = cells_[parent];
  const auto& x = slot_[slot];
  const int o = octant(up, x);
  Cell c{};
  c.half = 0.5 * up.half;
  c.cx = up.cx + ((o & 1) ? c.half : -c.half);
  c.cy = up.cy + ((o & 2) ? c.half : -c.half);
  c.cz = up.cz + ((o & 4) ? c.half : -c.half);
  c.m = x[3];
  c.mx = x[3] * x[0];
  c.my = x[3] * x[1];
  c.mz = x[3] * x[2];
  c.child.fill(-1);
  c.head = c.tail = slot;
  c.count = 1;
  c.depth = up.depth + 1;
  depth_ = std::max(depth_, int(c.depth));
  cells_[parent].child[std::size_t(o)] = std::int32_t(cells_.size());
  cells_.push_back(c);
}

template <class Real>
void Octree<Real>::insert(std::uint32_t slot) {
  const auto& x = slot_[slot];
  auto add_mass = [&](Cell& c) {
    c.m += x[3];
    c.mx += x[3] * x[0];
    c.my += x[3] * x[1];
    c.mz += x[3] * x[2];
  };
  std::uint32_t n = 0;
  add_mass(cells_[n]);
  for (;;) {
    Cell& c = cells_[n];
    if (c.internal) {
      const std::int32_t child = c.child[std::size_t(octant(c, x))];
      if (child < 0) return add_leaf(n, slot);
      n = std::uint32_t(child);
      add_mass(cells_[n]);
    } else if (c.count == 0) {  // the empty root
      c.head = c.tail = slot;
      c.count = 1;
      return;
    } else if (c.depth == max_depth) {  // coincident particles: keep a bucket
      next_[c.tail] = slot;
      c.tail = slot;
      ++c.count;
      return;
    } else {
      // Split: the resident particle moves one level down (its mass is already
      // counted here), then this node is internal and the loop places `slot`.
      const std::uint32_t resident = c.head;
      c.internal = true;
      c.count = 0;
      c.head = c.tail = npos;
      add_leaf(n, resident);
    }
  }
}

template <class Real>
void Octree<Real>::renumber(const ParticleSet<Real>& p, std::span<const std::uint32_t> members) {
  const std::size_t cells = cells_.size();
  // Children are created after their parents, so one backward pass sums sub-tree sizes.
  subtree_size_.assign(cells, 1);
  for (std::size_t n = cells; n-- > 0;)
    for (std::int32_t c : cells_[n].child)
      if (c >= 0) subtree_size_[n] += subtree_size_[std::size_t(c)];

  nodes_.clear();
  nodes_.reserve(cells);
  leaf_particle_.clear();
  leaf_x_.clear();
  leaf_y_.clear();
  leaf_z_.clear();
  leaf_m_.clear();
  leaf_of_.assign(members.size(), npos);
  std::vector<std::uint32_t> stack;
  if (cells > 0) stack.push_back(0);
  while (!stack.empty()) {
    const std::uint32_t cell = stack.back();
    stack.pop_back();
    const Cell& c = cells_[cell];
    const auto k = std::uint32_t(nodes_.size());
    Node node{};
    node.size = Real(2 * c.half);
    node.end = k + subtree_size_[cell];
    // Centre of mass Σ m·x / Σ m; a massless node sits at its cube's centre.
    const bool massive = c.m != 0;
    node.x = Real(massive ? c.mx / c.m : c.cx);
    node.y = Real(massive ? c.my / c.m : c.cy);
    node.z = Real(massive ? c.mz / c.m : c.cz);
    node.mass = Real(c.m);
    if (c.internal) {
      for (std::size_t o = 8; o-- > 0;)
        if (c.child[o] >= 0) stack.push_back(std::uint32_t(c.child[o]));
    } else {
      node.first = std::uint32_t(leaf_particle_.size());
      node.count = c.count;
      for (std::uint32_t s = c.head; s != npos; s = next_[s]) {
        const std::uint32_t j = members[s];
        leaf_particle_.push_back(j);
        leaf_x_.push_back(p.position.x[j]);
        leaf_y_.push_back(p.position.y[j]);
        leaf_z_.push_back(p.position.z[j]);
        leaf_m_.push_back(p.mass[j]);
        leaf_of_[s] = k;
      }
      if (c.count == 1) {  // exactly the particle: λ = 0 then adds the direct sum's terms
        node.x = leaf_x_[node.first];
        node.y = leaf_y_[node.first];
        node.z = leaf_z_[node.first];
        node.mass = leaf_m_[node.first];
      }
    }
    nodes_.push_back(node);
  }
}

template <class Real>
std::uint32_t Octree<Real>::walk(std::span<const std::uint32_t> entries, const Target& target, Real lambda2,
                                 Real eps2, Accumulator<Real>& acc, std::vector<std::uint32_t>& visit) const {
  visit.assign(entries.rbegin(), entries.rend());
  std::uint32_t visited = 0;
  while (!visit.empty()) {
    const std::uint32_t n = visit.back();
    visit.pop_back();
    ++visited;
    const Node& node = nodes_[n];
    const Real dx = node.x - target.x, dy = node.y - target.y, dz = node.z - target.z;
    if (node.count == 0) {
      if (accepts(n, target, lambda2)) {
        acc.add(dx, dy, dz, node.mass, eps2);
      } else {
        for (std::uint32_t c = n + 1; c < node.end; c = nodes_[c].end) visit.push_back(c);
      }
    } else if (node.count == 1) {
      if (n != target.leaf) acc.add(dx, dy, dz, node.mass, eps2);
    } else {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        if (leaf_particle_[k] == target.particle) continue;
        acc.add(leaf_x_[k] - target.x, leaf_y_[k] - target.y, leaf_z_[k] - target.z, leaf_m_[k], eps2);
      }
    }
  }
  return visited;
}

template class Octree<float>;
template class Octree<double>;

}  // namespace swirl::gravity
