// The locally essential tree: the top tree of nodes spanning ranks, each
// rank's subtrees, the export of what other ranks' group walks open, and the
// assembled tree walked by LinearOctree's group walk (essential_tree.hpp).
#include "swirl/gravity/essential_tree.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "swirl/parallel/for_blocks.hpp"
#include "tree_moments.hpp"

namespace swirl::gravity {

namespace {

constexpr int kLevels = LinearOctree<double>::kLevels;
constexpr std::uint64_t kKeyEnd = std::uint64_t(1) << 63;  // every 63-bit key is below
constexpr std::uint32_t npos = LinearOctree<double>::npos;
// The export's conservative opening test opens up to this relative distance
// squared beyond the walk's radius (the walk's Real rounding is ~1e-7 at worst).
constexpr double kExportMargin = 1e-4;

unsigned shift_of(int level) { return 3u * unsigned(kLevels - level); }

// A node of the global tree by its level and key prefix.
struct NodeId {
  std::uint8_t level = 0;
  std::uint64_t prefix = 0;
  std::uint64_t first_key() const { return prefix << shift_of(level); }
  std::uint64_t end_key() const { return (prefix + 1) << shift_of(level); }  // level 0: 2^63
  NodeId child(unsigned octant) const { return {std::uint8_t(level + 1), (prefix << 3) | octant}; }
  friend bool operator==(const NodeId&, const NodeId&) = default;
  friend bool operator<(const NodeId& a, const NodeId& b) {
    return a.level != b.level ? a.level < b.level : a.prefix < b.prefix;
  }
};

std::size_t count_in(std::span<const std::uint64_t> sorted, std::uint64_t first, std::uint64_t end) {
  const auto a = std::lower_bound(sorted.begin(), sorted.end(), first);
  return std::size_t(std::lower_bound(a, sorted.end(), end) - a);
}

// Bytes out, field by field (no padding travels).
class Writer {
 public:
  explicit Writer(dist::Bytes& bytes) : b_(bytes) {}
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::size_t at = b_.size();
    b_.resize(at + sizeof(T));
    std::memcpy(b_.data() + at, &v, sizeof(T));
  }
  template <class T>
  void put_array(const T* p, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = b_.size();
    b_.resize(at + n * sizeof(T));
    std::memcpy(b_.data() + at, p, n * sizeof(T));
  }

 private:
  dist::Bytes& b_;
};

class Reader {
 public:
  explicit Reader(const dist::Bytes& bytes) : b_(bytes) {}
  template <class T>
  T get() {
    T v;
    get_array(&v, 1);
    return v;
  }
  template <class T>
  void get_array(T* p, std::size_t n) {
    if (n == 0) return;
    if (b_.size() - at_ < n * sizeof(T)) throw std::runtime_error("essential tree: a message from a rank is truncated");
    std::memcpy(p, b_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
  }
  bool done() const { return at_ == b_.size(); }

 private:
  const dist::Bytes& b_;
  std::size_t at_ = 0;
};

void put_moments(Writer& w, const detail::NodeMoments& m) {
  for (const double v : {m.m, m.x, m.y, m.z, m.xx, m.xy, m.xz, m.yy, m.yz}) w.put(v);
}
detail::NodeMoments get_moments(Reader& r) {
  detail::NodeMoments m{};
  for (double* v : {&m.m, &m.x, &m.y, &m.z, &m.xx, &m.xy, &m.xz, &m.yy, &m.yz}) *v = r.get<double>();
  return m;
}

// A group of some rank, as the export sees it: global slots and box.
template <class Real>
struct GroupBox {
  std::uint32_t begin = 0, end = 0;
  Real lo[3] = {}, hi[3] = {};
};

// The export's opening test: true whenever the group walk's test
// (d_box² > open2 in Real: accept) could fail, i.e. whenever the walk could
// open the node. In double, with a relative margin.
template <class Real>
bool may_open(const GroupBox<Real>& g, Real cx, Real cy, Real cz, Real open2) {
  const double c[3] = {double(cx), double(cy), double(cz)};
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double e = std::max(std::max(double(g.lo[a]) - c[a], c[a] - double(g.hi[a])), 0.0);
    d2 += e * e;
  }
  return !(d2 > double(open2) * (1 + kExportMargin));
}

// The arrays of nodes being made (a LinearNodes with every array).
template <class Real>
void resize_nodes(LinearNodes<Real>& t, std::size_t n) {
  for (auto* a : {&t.com_x, &t.com_y, &t.com_z, &t.mass, &t.qxx, &t.qxy, &t.qxz, &t.qyy, &t.qyz, &t.open2})
    a->resize(n);
  t.begin.resize(n);
  t.end.resize(n);
  t.first_child.resize(n);
  t.child_count.resize(n);
  t.level.resize(n);
  t.prefix.resize(n);
}

template <class Real>
void copy_expansion(const LinearNodes<Real>& from, std::size_t i, LinearNodes<Real>& to, std::size_t j) {
  to.com_x[j] = from.com_x[i];
  to.com_y[j] = from.com_y[i];
  to.com_z[j] = from.com_z[i];
  to.mass[j] = from.mass[i];
  to.qxx[j] = from.qxx[i];
  to.qxy[j] = from.qxy[i];
  to.qxz[j] = from.qxz[i];
  to.qyy[j] = from.qyy[i];
  to.qyz[j] = from.qyz[i];
  to.open2[j] = from.open2[i];
}

// for_blocks over nodes, on the caller's thread when there are few.
template <class Body>
void node_blocks(std::size_t n, Body&& body) {
  constexpr std::size_t kBlock = 256;
  if (n <= kBlock) {
    if (n > 0) body(std::size_t(0), n, std::size_t(0));
    return;
  }
  parallel::for_blocks("essential_tree_nodes", n, kBlock, std::forward<Body>(body));
}

}  // namespace

template <class Real>
KeyCube global_key_cube(const dist::Communicator& comm, const ParticleSet<Real>& p) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::array<double, 3> lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < p.size(); ++i) {
      lo[std::size_t(a)] = std::min(lo[std::size_t(a)], double(p.position[a][i]));
      hi[std::size_t(a)] = std::max(hi[std::size_t(a)], double(p.position[a][i]));
    }
  comm.min(lo);
  comm.max(hi);
  return key_cube(lo, hi, std::size_t(comm.sum(std::uint64_t(p.size()))));
}

template <class Real>
void octree_keys(const ParticleSet<Real>& p, const KeyCube& cube, std::vector<std::uint64_t>& keys) {
  const double scale = key_scale(cube.side);
  keys.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    keys[i] = octree_key(double(p.position.x[i]), double(p.position.y[i]), double(p.position.z[i]), cube.corner,
                         scale);
}

std::vector<std::uint64_t> group_aligned_cuts(const dist::Communicator& comm, std::span<const std::uint64_t> keys,
                                              std::span<const std::uint64_t> cut_keys,
                                              const LinearTreeSettings& settings) {
  if (cut_keys.size() + 1 != std::size_t(comm.size()))
    throw std::invalid_argument("group_aligned_cuts: size()-1 cut keys are needed");
  if (!std::is_sorted(cut_keys.begin(), cut_keys.end()))
    throw std::invalid_argument("group_aligned_cuts: cut keys must be nondecreasing");
  std::vector<std::uint64_t> sorted(keys.begin(), keys.end());
  std::sort(sorted.begin(), sorted.end());
  // For every cut and every level whose node holds the cut strictly inside:
  // the global count of the node, and of its part below the cut.
  const std::size_t cuts = cut_keys.size();
  auto holds = [](std::uint64_t c, int level) {
    const NodeId id{std::uint8_t(level), c >> shift_of(level)};
    return c > 0 && c < kKeyEnd && id.first_key() < c;
  };
  std::vector<std::uint64_t> counts(cuts * kLevels * 2, 0);
  for (std::size_t i = 0; i < cuts; ++i)
    for (int level = 0; level < kLevels; ++level) {
      const std::uint64_t c = cut_keys[i];
      if (!holds(c, level)) continue;
      const NodeId id{std::uint8_t(level), c >> shift_of(level)};
      const std::size_t at = (i * kLevels + std::size_t(level)) * 2;
      counts[at] = count_in(sorted, id.first_key(), id.end_key());
      counts[at + 1] = count_in(sorted, id.first_key(), c);
    }
  comm.sum(counts);
  std::vector<std::uint64_t> aligned(cut_keys.begin(), cut_keys.end());
  for (std::size_t i = 0; i < cuts; ++i) {
    // Down the nodes holding the cut: stop at the first that is a group or a
    // leaf (holding it strictly inside), or when none holds it or it is empty.
    for (int level = 0; level < kLevels; ++level) {
      const std::uint64_t c = cut_keys[i];
      if (!holds(c, level)) break;
      const std::size_t at = (i * kLevels + std::size_t(level)) * 2;
      const std::uint64_t count = counts[at], below = counts[at + 1];
      if (count == 0) break;
      if (count <= settings.group_size || count <= settings.bucket_size) {
        const NodeId id{std::uint8_t(level), c >> shift_of(level)};
        aligned[i] = below <= count - below ? id.first_key() : id.end_key();
        break;
      }
    }
  }
  if (!std::is_sorted(aligned.begin(), aligned.end()))
    throw std::logic_error("group_aligned_cuts: the aligned cuts are out of order");
  return aligned;
}

template <class Real>
void EssentialTree<Real>::build(const dist::Communicator& comm, const ParticleSet<Real>& p,
                                std::span<const std::uint64_t> keys, std::uint64_t first_global_index,
                                std::span<const std::uint64_t> cut_keys, const KeyCube& cube,
                                const LinearTreeSettings& settings, std::size_t block_size,
                                const ActiveSet& active) {
  const int rank = comm.rank(), ranks = comm.size();
  const std::size_t n = p.size();
  if (settings.walk != Walk::Group) throw std::invalid_argument("essential tree: needs walk = group");
  if (settings.bucket_size < 1 || settings.group_size < 1 || block_size < 1)
    throw std::invalid_argument("essential tree: bucket, group and block sizes must be at least 1");
  if (keys.size() != n) throw std::invalid_argument("essential tree: one key per particle is needed");
  if (cut_keys.size() + 1 != std::size_t(ranks)) throw std::invalid_argument("essential tree: size()-1 cuts are needed");
  if (!std::is_sorted(cut_keys.begin(), cut_keys.end()))
    throw std::invalid_argument("essential tree: cut keys must be nondecreasing");
  if (!std::is_sorted(keys.begin(), keys.end())) throw std::invalid_argument("essential tree: keys must be sorted");
  const std::uint64_t range_lo = rank > 0 ? cut_keys[std::size_t(rank) - 1] : 0;
  const std::uint64_t range_hi = rank + 1 < ranks ? std::min(cut_keys[std::size_t(rank)], kKeyEnd) : kKeyEnd;
  if (n > 0 && (keys.front() < range_lo || keys.back() >= range_hi))
    throw std::invalid_argument("essential tree: a particle's key is outside this rank's key range");
  const std::uint64_t global_n = comm.sum(std::uint64_t(n));
  if (global_n >= npos) throw std::invalid_argument("essential tree: too many particles for 32-bit slots");
  if (comm.exclusive_prefix_sum(n) != first_global_index)
    throw std::invalid_argument("essential tree: first_global_index is not the particles below this rank");
  block_size_ = block_size;
  stats_ = {};
  const detail::CubeFrame frame{cube.corner, cube.side};
  const bool quadrupole = settings.multipole == Multipole::Quadrupole;
  const auto first = std::uint32_t(first_global_index);
  const Real *px = p.position.x.data(), *py = p.position.y.data(), *pz = p.position.z.data(), *pm = p.mass.data();

  // 1. Candidates (nodes holding a cut strictly inside), their counts per
  //    rank, and the spanning ones.
  std::vector<NodeId> candidates;
  for (const std::uint64_t c : cut_keys)
    for (int level = 0; level < kLevels; ++level) {
      const NodeId id{std::uint8_t(level), c < kKeyEnd ? c >> shift_of(level) : 0};
      if (c > 0 && c < kKeyEnd && id.first_key() < c) candidates.push_back(id);
    }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  dist::Bytes mine;
  {
    Writer w(mine);
    for (const NodeId& id : candidates) w.put(std::uint64_t(count_in(keys, id.first_key(), id.end_key())));
  }
  const std::vector<dist::Bytes> all_counts = comm.all_gather(mine);
  std::vector<NodeId> spanning;
  for (const dist::Bytes& b : all_counts) stats_.bytes_gathered += b.size();
  {
    std::vector<std::uint64_t> total(candidates.size(), 0), holders(candidates.size(), 0);
    for (const dist::Bytes& b : all_counts) {
      Reader r(b);
      for (std::size_t k = 0; k < candidates.size(); ++k) {
        const auto count = r.get<std::uint64_t>();
        total[k] += count;
        holders[k] += count > 0 ? 1 : 0;
      }
      if (!r.done()) throw std::runtime_error("essential tree: a rank sent other candidates");
    }
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (holders[k] < 2) continue;
      // A spanning node must be split and not a group: otherwise a group or
      // a leaf has particles on two ranks.
      if (total[k] <= settings.group_size || total[k] <= settings.bucket_size || candidates[k].level >= kLevels)
        throw std::invalid_argument(
            "essential tree: the cuts split a group or a leaf of the global tree (cut with group_aligned_cuts)");
      spanning.push_back(candidates[k]);
    }
  }
  auto is_spanning = [&](const NodeId& id) { return std::binary_search(spanning.begin(), spanning.end(), id); };
  stats_.spanning_nodes = spanning.size();

  // 2. This rank's local roots, in key order.
  std::vector<NodeId> roots;
  if (spanning.empty()) {
    if (n > 0) roots.push_back(NodeId{});
  } else {
    for (const NodeId& s : spanning)
      for (unsigned o = 0; o < 8; ++o) {
        const NodeId c = s.child(o);
        if (!is_spanning(c) && count_in(keys, c.first_key(), c.end_key()) > 0) roots.push_back(c);
      }
    std::sort(roots.begin(), roots.end(),
              [](const NodeId& a, const NodeId& b) { return a.first_key() < b.first_key(); });
  }

  // 3. The subtrees of the local roots (one-rank rules), generation by
  //    generation: roots first, each node's children contiguous, in octant order.
  LinearNodes<Real> own;
  std::vector<detail::NodeMoments> own_moments;
  const std::size_t own_roots = roots.size();
  {
    resize_nodes(own, own_roots);
    for (std::size_t k = 0; k < own_roots; ++k) {
      own.begin[k] = std::uint32_t(count_in(keys, 0, roots[k].first_key()));
      own.end[k] = std::uint32_t(count_in(keys, 0, roots[k].end_key()));
      own.level[k] = roots[k].level;
      own.prefix[k] = roots[k].prefix;
      own.first_child[k] = npos;
      own.child_count[k] = 0;
    }
    std::vector<std::size_t> generation{0};
    std::vector<std::array<std::uint32_t, 9>> bounds;
    for (std::size_t gb = 0, ge = own_roots; gb < ge;) {
      bounds.resize(ge - gb);
      node_blocks(ge - gb, [&](std::size_t b, std::size_t e, std::size_t) {
        for (std::size_t k = b; k < e; ++k) {
          const std::size_t node = gb + k;
          const std::uint32_t lo = own.begin[node], hi = own.end[node];
          auto& bound = bounds[k];
          bound.fill(lo);
          unsigned children = 0;
          if (hi - lo > settings.bucket_size && own.level[node] < kLevels) {
            const unsigned shift = 3u * unsigned(kLevels - 1 - own.level[node]);
            bound[8] = hi;
            for (std::uint64_t c = 1; c < 8; ++c)
              bound[c] = std::uint32_t(std::partition_point(keys.begin() + lo, keys.begin() + hi,
                                                            [&](std::uint64_t key) { return ((key >> shift) & 7u) < c; }) -
                                       keys.begin());
            for (std::size_t c = 0; c < 8; ++c) children += bound[c] < bound[c + 1] ? 1u : 0u;
          }
          own.child_count[node] = std::uint8_t(children);
        }
      });
      std::size_t next = ge;
      for (std::size_t node = gb; node < ge; ++node) {
        own.first_child[node] = own.child_count[node] ? std::uint32_t(next) : npos;
        next += own.child_count[node];
      }
      resize_nodes(own, next);
      for (std::size_t node = gb; node < ge; ++node) {
        if (!own.child_count[node]) continue;
        std::uint32_t child = own.first_child[node];
        const auto& bound = bounds[node - gb];
        for (std::uint64_t c = 0; c < 8; ++c) {
          if (bound[c] == bound[c + 1]) continue;
          own.begin[child] = bound[c];
          own.end[child] = bound[c + 1];
          own.level[child] = std::uint8_t(own.level[node] + 1);
          own.prefix[child] = (own.prefix[node] << 3) | c;
          own.first_child[child] = npos;
          own.child_count[child] = 0;
          ++child;
        }
      }
      gb = ge;
      ge = next;
      generation.push_back(gb);
    }
    // Moments, the deepest generation first (children after their parents).
    own_moments.resize(own.size());
    for (std::size_t g = generation.size() - 1; g-- > 0;) {
      const std::size_t gb = generation[g], ge = generation[g + 1];
      node_blocks(ge - gb, [&](std::size_t b, std::size_t e, std::size_t) {
        for (std::size_t node = gb + b; node < gb + e; ++node) {
          if (own.child_count[node] == 0)
            own_moments[node] = detail::leaf_moments(px, py, pz, pm, own.begin[node], own.end[node], own.level[node],
                                                     own.prefix[node], frame, quadrupole);
          else
            own_moments[node] = detail::parent_moments(own_moments.data() + own.first_child[node],
                                                       own.child_count[node], own.level[node], own.prefix[node], frame,
                                                       quadrupole);
        }
      });
    }
    node_blocks(own.size(), [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t node = b; node < e; ++node)
        detail::store_node(own_moments[node], own.level[node], own.prefix[node], frame, settings, own, node);
    });
  }

  // 4. Every rank's local roots (all-gather), and the top tree: the spanning
  //    nodes breadth first from the root, children contiguous in octant order,
  //    the local roots among them.
  struct Root {
    NodeId id;
    int rank = 0;
    std::size_t index = 0;  // among its rank's roots
    std::uint32_t begin = 0, end = 0;  // global slots
    std::uint8_t child_count = 0;
    detail::NodeMoments moments{};
  };
  std::vector<Root> all_roots;
  std::vector<std::size_t> roots_of_rank(std::size_t(ranks) + 1, 0);  // all_roots index of each rank's first
  {
    dist::Bytes b;
    Writer w(b);
    for (std::size_t k = 0; k < own_roots; ++k) {
      w.put(roots[k].level);
      w.put(roots[k].prefix);
      w.put(first + own.begin[k]);
      w.put(first + own.end[k]);
      w.put(own.child_count[k]);
      put_moments(w, own_moments[k]);
    }
    const std::vector<dist::Bytes> all = comm.all_gather(b);
    for (int s = 0; s < ranks; ++s) {
      stats_.bytes_gathered += all[std::size_t(s)].size();
      roots_of_rank[std::size_t(s)] = all_roots.size();
      Reader r(all[std::size_t(s)]);
      for (std::size_t k = 0; !r.done(); ++k) {
        Root root;
        root.id.level = r.get<std::uint8_t>();
        root.id.prefix = r.get<std::uint64_t>();
        root.rank = s;
        root.index = k;
        root.begin = r.get<std::uint32_t>();
        root.end = r.get<std::uint32_t>();
        root.child_count = r.get<std::uint8_t>();
        root.moments = get_moments(r);
        all_roots.push_back(root);
      }
    }
    roots_of_rank[std::size_t(ranks)] = all_roots.size();
  }
  stats_.local_roots = all_roots.size();
  std::vector<std::size_t> roots_by_id(all_roots.size());
  for (std::size_t k = 0; k < roots_by_id.size(); ++k) roots_by_id[k] = k;
  std::sort(roots_by_id.begin(), roots_by_id.end(),
            [&](std::size_t a, std::size_t b) { return all_roots[a].id < all_roots[b].id; });
  auto find_root = [&](const NodeId& id) -> std::size_t {
    const auto it = std::lower_bound(roots_by_id.begin(), roots_by_id.end(), id,
                                     [&](std::size_t k, const NodeId& v) { return all_roots[k].id < v; });
    return it != roots_by_id.end() && all_roots[*it].id == id ? *it : npos;
  };

  // The top tree: top_root[i] is the all_roots index of a local root (npos: spanning).
  LinearNodes<Real> top;
  std::vector<std::size_t> top_root;
  std::vector<std::uint32_t> top_gbegin, top_gend;
  std::vector<detail::NodeMoments> top_moments;
  {
    std::vector<NodeId> ids;
    auto push = [&](const NodeId& id, std::size_t root) {
      ids.push_back(id);
      top_root.push_back(root);
    };
    if (spanning.empty()) {
      if (all_roots.size() > 1) throw std::logic_error("essential tree: several roots without a spanning node");
      if (!all_roots.empty()) push(all_roots[0].id, 0);
    } else {
      push(NodeId{}, npos);
      if (!is_spanning(NodeId{})) throw std::logic_error("essential tree: spanning nodes without a spanning root");
    }
    std::vector<std::uint32_t> first_child, child_count;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      first_child.push_back(npos);
      child_count.push_back(0);
      if (top_root[i] != npos) continue;
      first_child[i] = std::uint32_t(ids.size());
      for (unsigned o = 0; o < 8; ++o) {
        const NodeId c = ids[i].child(o);
        if (is_spanning(c)) {
          push(c, npos);
        } else {
          const std::size_t k = find_root(c);
          if (k == npos) continue;  // no particle anywhere in this octant
          push(c, k);
        }
        ++child_count[i];
      }
      if (child_count[i] == 0) throw std::logic_error("essential tree: a spanning node without children");
    }
    const std::size_t count = ids.size();
    if (count - spanning.size() != all_roots.size())
      throw std::logic_error("essential tree: a local root is not a child of a spanning node");
    resize_nodes(top, count);
    top_gbegin.resize(count);
    top_gend.resize(count);
    top_moments.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      top.level[i] = ids[i].level;
      top.prefix[i] = ids[i].prefix;
      top.first_child[i] = first_child[i];
      top.child_count[i] = std::uint8_t(child_count[i]);
    }
    // Moments bottom-up: breadth first, so children come after their parent.
    for (std::size_t i = count; i-- > 0;) {
      if (top_root[i] != npos) {
        const Root& r = all_roots[top_root[i]];
        top_moments[i] = r.moments;
        top_gbegin[i] = r.begin;
        top_gend[i] = r.end;
        top.child_count[i] = r.child_count;  // as in the global tree (0: a leaf)
        top.first_child[i] = npos;
      } else {
        const std::uint32_t c0 = top.first_child[i], cc = top.child_count[i];
        top_moments[i] = detail::parent_moments(top_moments.data() + c0, cc, top.level[i], top.prefix[i], frame,
                                                quadrupole);
        top_gbegin[i] = top_gbegin[c0];
        top_gend[i] = top_gend[c0 + cc - 1];
      }
      detail::store_node(top_moments[i], top.level[i], top.prefix[i], frame, settings, top, i);
    }
  }
  const std::size_t top_count = top.size();
  // The top index of each of this rank's roots.
  std::vector<std::uint32_t> own_root_top(own_roots, npos);
  for (std::size_t i = 0; i < top_count; ++i)
    if (top_root[i] != npos && all_roots[top_root[i]].rank == rank)
      own_root_top[all_roots[top_root[i]].index] = std::uint32_t(i);

  // 5. This rank's groups (curve order) and every rank's group boxes.
  std::vector<std::uint32_t> own_groups;  // own-subtree node indices
  for (std::size_t k = 0; k < own_roots; ++k) {
    std::vector<std::uint32_t> stack{std::uint32_t(k)};
    while (!stack.empty()) {
      const std::uint32_t node = stack.back();
      stack.pop_back();
      if (own.child_count[node] == 0 || own.end[node] - own.begin[node] <= settings.group_size) {
        own_groups.push_back(node);
        continue;
      }
      for (std::uint32_t c = own.first_child[node] + own.child_count[node]; c-- > own.first_child[node];)
        stack.push_back(c);
    }
  }
  stats_.groups = own_groups.size();
  // Each own group's box: of its particles, or with a partly active set of
  // its active ones (the box LinearOctree::walk_group tests against; a group
  // without one is not walked, so its box is not sent).
  struct OwnBox {
    bool walked = false;
    Real lo[3] = {}, hi[3] = {};
  };
  std::vector<OwnBox> own_boxes(own_groups.size());
  node_blocks(own_groups.size(), [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t g = b; g < e; ++g) {
      OwnBox& box = own_boxes[g];
      for (std::uint32_t s = own.begin[own_groups[g]]; s < own.end[own_groups[g]]; ++s) {
        if (!active.contains(s)) continue;
        const Real x[3] = {px[s], py[s], pz[s]};
        for (int a = 0; a < 3; ++a) {
          box.lo[a] = box.walked ? std::min(box.lo[a], x[a]) : x[a];
          box.hi[a] = box.walked ? std::max(box.hi[a], x[a]) : x[a];
        }
        box.walked = true;
      }
    }
  });
  std::vector<std::vector<GroupBox<Real>>> boxes(static_cast<std::size_t>(ranks));
  {
    dist::Bytes b;
    Writer w(b);
    for (std::size_t g = 0; g < own_groups.size(); ++g) {
      if (!own_boxes[g].walked) continue;
      w.put(first + own.begin[own_groups[g]]);
      w.put(first + own.end[own_groups[g]]);
      w.put_array(own_boxes[g].lo, 3);
      w.put_array(own_boxes[g].hi, 3);
    }
    const std::vector<dist::Bytes> all = comm.all_gather(b);
    for (int s = 0; s < ranks; ++s) {
      stats_.bytes_gathered += all[std::size_t(s)].size();
      if (s == rank) continue;
      Reader r(all[std::size_t(s)]);
      while (!r.done()) {
        GroupBox<Real> g;
        g.begin = r.get<std::uint32_t>();
        g.end = r.get<std::uint32_t>();
        r.get_array(g.lo, 3);
        r.get_array(g.hi, 3);
        boxes[std::size_t(s)].push_back(g);
      }
    }
  }

  // 6. Export to every other rank: what its groups' walks can open below
  //    this rank's local roots. Message: one flag per local root of this rank
  //    (opened), then, breadth first, the children of every opened internal
  //    node (one record each: expansion, global slots, child count, opened),
  //    then the particles of the opened leaves in slot order.
  std::vector<dist::Bytes> send(static_cast<std::size_t>(ranks));
  for (int d = 0; d < ranks; ++d) {
    if (d == rank) continue;
    const std::vector<GroupBox<Real>>& groups = boxes[std::size_t(d)];
    // Which groups of d reach each of this rank's roots (the top tree replayed).
    std::vector<std::vector<std::uint32_t>> visitors(own_roots);
    if (own_roots > 0) {
      std::vector<std::uint32_t> stack;
      for (std::uint32_t g = 0; g < groups.size(); ++g) {
        const GroupBox<Real>& box = groups[g];
        stack.assign(1, 0);
        while (!stack.empty()) {
          const std::uint32_t i = stack.back();
          stack.pop_back();
          if (top_root[i] != npos) {
            if (all_roots[top_root[i]].rank == rank) visitors[all_roots[top_root[i]].index].push_back(g);
            continue;
          }
          const bool ancestor = top_gbegin[i] <= box.begin && box.end <= top_gend[i];
          if (ancestor || may_open(box, top.com_x[i], top.com_y[i], top.com_z[i], top.open2[i]))
            for (std::uint32_t c = 0; c < top.child_count[i]; ++c) stack.push_back(top.first_child[i] + c);
        }
      }
    }
    Writer w(send[std::size_t(d)]);
    std::vector<std::uint32_t> lists;                            // group lists of queued nodes
    std::vector<std::array<std::uint32_t, 3>> queue;              // node, list begin, list end
    std::vector<std::uint32_t> leaves;                            // opened leaves
    auto opened_by = [&](std::uint32_t node, std::span<const std::uint32_t> visiting) {
      const std::size_t at = lists.size();
      for (const std::uint32_t g : visiting)
        if (may_open(groups[g], own.com_x[node], own.com_y[node], own.com_z[node], own.open2[node]))
          lists.push_back(g);
      return std::array<std::uint32_t, 3>{node, std::uint32_t(at), std::uint32_t(lists.size())};
    };
    auto enqueue = [&](const std::array<std::uint32_t, 3>& q) {
      const bool opened = q[2] > q[1];
      if (opened) {
        if (own.child_count[q[0]] == 0)
          leaves.push_back(q[0]);
        else
          queue.push_back(q);
      } else {
        lists.resize(q[1]);
      }
      return opened;
    };
    for (std::uint32_t k = 0; k < own_roots; ++k)
      w.put(std::uint8_t(enqueue(opened_by(k, visitors[k])) ? 1 : 0));
    std::uint64_t records = 0;
    for (std::size_t qi = 0; qi < queue.size(); ++qi) {
      const auto q = queue[qi];
      // A copy: opened_by appends to lists.
      const std::vector<std::uint32_t> visiting(lists.begin() + q[1], lists.begin() + q[2]);
      for (std::uint32_t c = own.first_child[q[0]]; c < own.first_child[q[0]] + own.child_count[q[0]]; ++c) {
        const bool opened = enqueue(opened_by(c, visiting));
        for (const Real v : {own.com_x[c], own.com_y[c], own.com_z[c], own.mass[c], own.qxx[c], own.qxy[c],
                             own.qxz[c], own.qyy[c], own.qyz[c], own.open2[c]})
          w.put(v);
        w.put(first + own.begin[c]);
        w.put(first + own.end[c]);
        w.put(own.child_count[c]);
        w.put(std::uint8_t(opened ? 1 : 0));
        ++records;
      }
    }
    std::sort(leaves.begin(), leaves.end(),
              [&](std::uint32_t a, std::uint32_t b) { return own.begin[a] < own.begin[b]; });
    std::uint64_t particles = 0;
    for (const std::uint32_t leaf : leaves) {
      const std::uint32_t b = own.begin[leaf], e = own.end[leaf];
      w.put_array(px + b, e - b);
      w.put_array(py + b, e - b);
      w.put_array(pz + b, e - b);
      w.put_array(pm + b, e - b);
      particles += e - b;
    }
    stats_.nodes_sent += records;
    stats_.particles_sent += particles;
    stats_.bytes_sent += send[std::size_t(d)].size();
  }
  const std::vector<dist::Bytes> received = comm.all_to_all(send);
  send.clear();

  // 7. Read what the other ranks sent (the same breadth-first order).
  struct Import {
    std::vector<std::uint8_t> root_opened;        // per local root of the sender
    std::vector<std::uint32_t> root_first_child;  // record index (npos: none)
    LinearNodes<Real> nodes;                      // the records; begin/end global, first_child a record index
    std::vector<std::uint8_t> opened;             // per record
    std::vector<std::array<std::uint32_t, 2>> leaves;  // opened leaves' global slots, in slot order
    AlignedVector<Real> x, y, z, m;                    // their particles
  };
  std::vector<Import> imports(static_cast<std::size_t>(ranks));
  for (int s = 0; s < ranks; ++s) {
    if (s == rank) continue;
    Import& im = imports[std::size_t(s)];
    Reader r(received[std::size_t(s)]);
    stats_.bytes_received += received[std::size_t(s)].size();
    const std::size_t root_begin = roots_of_rank[std::size_t(s)];
    const std::size_t root_count = roots_of_rank[std::size_t(s) + 1] - root_begin;
    im.root_opened.resize(root_count);
    im.root_first_child.assign(root_count, npos);
    struct Parent {
      bool root;
      std::uint32_t index;
    };
    std::vector<Parent> parents;
    for (std::size_t k = 0; k < root_count; ++k) {
      im.root_opened[k] = r.get<std::uint8_t>();
      const Root& root = all_roots[root_begin + k];
      if (!im.root_opened[k]) continue;
      if (root.child_count == 0)
        im.leaves.push_back({root.begin, root.end});
      else
        parents.push_back({true, std::uint32_t(k)});
    }
    for (std::size_t qi = 0; qi < parents.size(); ++qi) {
      const Parent parent = parents[qi];
      const std::size_t at = im.nodes.size();
      std::uint32_t cc = 0;
      std::uint8_t level = 0;
      if (parent.root) {
        const Root& root = all_roots[root_begin + parent.index];
        cc = root.child_count;
        level = std::uint8_t(root.id.level + 1);
        im.root_first_child[parent.index] = std::uint32_t(at);
      } else {
        cc = im.nodes.child_count[parent.index];
        level = std::uint8_t(im.nodes.level[parent.index] + 1);
        im.nodes.first_child[parent.index] = std::uint32_t(at);
      }
      resize_nodes(im.nodes, at + cc);
      im.opened.resize(at + cc);
      for (std::size_t c = at; c < at + cc; ++c) {
        for (AlignedVector<Real>* a : {&im.nodes.com_x, &im.nodes.com_y, &im.nodes.com_z, &im.nodes.mass,
                                       &im.nodes.qxx, &im.nodes.qxy, &im.nodes.qxz, &im.nodes.qyy, &im.nodes.qyz,
                                       &im.nodes.open2})
          (*a)[c] = r.get<Real>();
        im.nodes.begin[c] = r.get<std::uint32_t>();
        im.nodes.end[c] = r.get<std::uint32_t>();
        im.nodes.child_count[c] = r.get<std::uint8_t>();
        im.opened[c] = r.get<std::uint8_t>();
        im.nodes.level[c] = level;
        im.nodes.prefix[c] = 0;  // not sent: the walk never reads it
        im.nodes.first_child[c] = npos;
        if (!im.opened[c]) continue;
        if (im.nodes.child_count[c] == 0)
          im.leaves.push_back({im.nodes.begin[c], im.nodes.end[c]});
        else
          parents.push_back({false, std::uint32_t(c)});
      }
    }
    std::sort(im.leaves.begin(), im.leaves.end());
    for (const auto& leaf : im.leaves) {
      const std::size_t count = leaf[1] - leaf[0], at = im.x.size();
      for (AlignedVector<Real>* a : {&im.x, &im.y, &im.z, &im.m}) {
        a->resize(at + count);
        r.get_array(a->data() + at, count);
      }
    }
    if (!r.done()) throw std::runtime_error("essential tree: a rank sent more than its tree");
    stats_.nodes_received += im.nodes.size();
    stats_.particles_received += im.x.size();
  }

  // 8. The assembled tree. Nodes: the top tree, this rank's subtrees below
  //    its roots, then each other rank's records in rank order. Particles:
  //    in global slot order (the ranks in order, this rank's own among them),
  //    so that every node's range of them nests as its global range does.
  std::vector<std::size_t> import_base(std::size_t(ranks), 0);
  std::size_t total = top_count + (own.size() - own_roots);
  for (int s = 0; s < ranks; ++s) {
    import_base[std::size_t(s)] = total;
    total += imports[std::size_t(s)].nodes.size();
  }
  auto own_index = [&](std::uint32_t k) -> std::uint32_t {
    return k < own_roots ? own_root_top[k] : std::uint32_t(top_count + k - own_roots);
  };
  struct Interval {
    std::uint32_t begin, end;  // global slots
    std::size_t at;            // local slot of begin
  };
  std::vector<Interval> present;
  AlignedVector<Real> tx, ty, tz, tm;
  for (int s = 0; s < ranks; ++s) {
    if (s == rank) {
      own_offset_ = tx.size();
      if (n > 0) present.push_back({first, std::uint32_t(first + n), tx.size()});
      tx.insert(tx.end(), px, px + n);
      ty.insert(ty.end(), py, py + n);
      tz.insert(tz.end(), pz, pz + n);
      tm.insert(tm.end(), pm, pm + n);
      continue;
    }
    const Import& im = imports[std::size_t(s)];
    std::size_t at = tx.size();
    for (const auto& leaf : im.leaves) {
      present.push_back({leaf[0], leaf[1], at});
      at += leaf[1] - leaf[0];
    }
    tx.insert(tx.end(), im.x.begin(), im.x.end());
    ty.insert(ty.end(), im.y.begin(), im.y.end());
    tz.insert(tz.end(), im.z.begin(), im.z.end());
    tm.insert(tm.end(), im.m.begin(), im.m.end());
  }
  // The local slot of global slot g: how many present particles lie below it.
  auto local_slot = [&](std::uint32_t g) -> std::uint32_t {
    const auto it = std::upper_bound(present.begin(), present.end(), g,
                                     [](std::uint32_t v, const Interval& i) { return v < i.begin; });
    if (it == present.begin()) return 0;
    const Interval& i = *(it - 1);
    return std::uint32_t(i.at + std::min(g - i.begin, i.end - i.begin));
  };

  LinearNodes<Real> t;
  resize_nodes(t, total);
  std::vector<std::uint8_t> complete(total, 1);
  std::vector<std::uint8_t> imported(total, 0);  // 1: a record another rank sent, 2: another rank's root
  auto set_range = [&](std::size_t j, std::uint32_t gbegin, std::uint32_t gend) {
    t.begin[j] = local_slot(gbegin);
    t.end[j] = local_slot(gend);
  };
  for (std::size_t i = 0; i < top_count; ++i) {
    copy_expansion(top, i, t, i);
    t.level[i] = top.level[i];
    t.prefix[i] = top.prefix[i];
    set_range(i, top_gbegin[i], top_gend[i]);
    t.child_count[i] = 0;
    t.first_child[i] = npos;
    if (top_root[i] == npos) {
      t.child_count[i] = top.child_count[i];
      t.first_child[i] = top.first_child[i];
      continue;
    }
    const Root& root = all_roots[top_root[i]];
    if (root.rank == rank) {
      t.child_count[i] = own.child_count[root.index];
      if (t.child_count[i]) t.first_child[i] = own_index(own.first_child[root.index]);
      continue;
    }
    const Import& im = imports[std::size_t(root.rank)];
    imported[i] = 2;
    if (!im.root_opened[root.index]) {
      complete[i] = 0;  // never opened by this rank's walks: its expansion only
    } else if (root.child_count) {
      t.child_count[i] = root.child_count;
      t.first_child[i] = std::uint32_t(import_base[std::size_t(root.rank)] + im.root_first_child[root.index]);
    }
  }
  for (std::uint32_t k = std::uint32_t(own_roots); k < own.size(); ++k) {
    const std::uint32_t j = own_index(k);
    copy_expansion(own, k, t, j);
    t.level[j] = own.level[k];
    t.prefix[j] = own.prefix[k];
    set_range(j, first + own.begin[k], first + own.end[k]);
    t.child_count[j] = own.child_count[k];
    t.first_child[j] = own.child_count[k] ? own_index(own.first_child[k]) : npos;
  }
  for (int s = 0; s < ranks; ++s) {
    const Import& im = imports[std::size_t(s)];
    const std::size_t base = import_base[std::size_t(s)];
    for (std::size_t c = 0; c < im.nodes.size(); ++c) {
      const std::size_t j = base + c;
      imported[j] = 1;
      copy_expansion(im.nodes, c, t, j);
      t.level[j] = im.nodes.level[c];
      t.prefix[j] = 0;
      set_range(j, im.nodes.begin[c], im.nodes.end[c]);
      t.child_count[j] = 0;
      t.first_child[j] = npos;
      if (!im.opened[c]) {
        complete[j] = 0;
      } else if (im.nodes.child_count[c]) {
        t.child_count[j] = im.nodes.child_count[c];
        t.first_child[j] = std::uint32_t(base + im.nodes.first_child[c]);
      }
    }
  }
  std::vector<std::uint32_t> groups(own_groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) groups[g] = own_index(own_groups[g]);

  // 9. On checked builds (the first, then every check_every-th: the replay
  //    costs about twice the rest of build()), this rank's walks replayed
  //    with the group walk's own test: every node they open must have its
  //    children or its particles here. (And what of the import they use: the
  //    export's excess over the walks' needs.)
  const bool check = check_every_ > 0 && builds_++ % check_every_ == 0;
  std::vector<std::uint8_t> used(check ? total : 0, 0);  // bit 0: visited, bit 1: opened as a leaf
  for (std::size_t g = 0; check && g < groups.size(); ++g) {
    if (!own_boxes[g].walked) continue;
    const std::uint32_t group = groups[g];
    const std::uint32_t gb = t.begin[group], ge = t.end[group];
    const Real *lo = own_boxes[g].lo, *hi = own_boxes[g].hi;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
      const std::uint32_t node = stack.back();
      stack.pop_back();
      if (node == group) continue;
      used[node] |= 1;
      if (!(t.begin[node] <= gb && ge <= t.end[node])) {
        const Real cx = t.com_x[node], cy = t.com_y[node], cz = t.com_z[node];
        const Real ex = std::max(std::max(lo[0] - cx, cx - hi[0]), Real(0));
        const Real ey = std::max(std::max(lo[1] - cy, cy - hi[1]), Real(0));
        const Real ez = std::max(std::max(lo[2] - cz, cz - hi[2]), Real(0));
        if (ex * ex + ey * ey + ez * ez > t.open2[node]) continue;
      }
      if (!complete[node])
        throw std::logic_error("essential tree: a walk of rank " + std::to_string(rank) +
                               " opens a node another rank did not send");
      if (imported[node] && t.child_count[node] == 0) used[node] |= 2;
      for (std::uint32_t c = 0; c < t.child_count[node]; ++c) stack.push_back(t.first_child[node] + c);
    }
  }

  stats_.checked = check;
  for (std::size_t j = 0; j < used.size(); ++j) {
    if (imported[j] == 1 && (used[j] & 1)) ++stats_.nodes_used;
    if (imported[j] && (used[j] & 2)) stats_.particles_used += t.end[j] - t.begin[j];
  }
  stats_.tree_nodes = total;
  stats_.tree_particles = tx.size();
  own_count_ = n;
  slot_active_.clear();
  if (!active.all()) {  // the assembled tree's slots: this rank's particles at own_offset_, none other active
    slot_active_.assign(tx.size(), 0);
    for (std::size_t i = 0; i < n; ++i) slot_active_[own_offset_ + i] = active.contains(i) ? 1 : 0;
  }
  tree_.assemble(std::move(t), tx, ty, tz, tm, std::move(groups), settings);
}

template <class Real>
WalkCounts EssentialTree<Real>::evaluate(GravityField<Real>& out) {
  const ActiveSet active = slot_active_.empty() ? ActiveSet{} : ActiveSet{slot_active_.data(), 1};
  const WalkCounts counts = tree_.evaluate(field_, block_size_, active);
  out.resize(own_count_);
  for (std::size_t i = 0; i < own_count_; ++i) {
    out.acceleration.x[i] = field_.acceleration.x[own_offset_ + i];
    out.acceleration.y[i] = field_.acceleration.y[own_offset_ + i];
    out.acceleration.z[i] = field_.acceleration.z[own_offset_ + i];
    out.potential[i] = field_.potential[own_offset_ + i];
  }
  return counts;
}

template <class Real>
void EssentialTree<Real>::add_walk_costs(std::span<std::uint64_t> out) const {
  if (out.size() != own_count_) throw std::logic_error("essential tree: walk costs for another particle count");
  std::vector<std::uint64_t> all(tree_.x().size(), 0);
  tree_.add_walk_costs(all);
  for (std::size_t i = 0; i < own_count_; ++i) out[i] += all[own_offset_ + i];
}

template KeyCube global_key_cube<float>(const dist::Communicator&, const ParticleSet<float>&);
template KeyCube global_key_cube<double>(const dist::Communicator&, const ParticleSet<double>&);
template void octree_keys<float>(const ParticleSet<float>&, const KeyCube&, std::vector<std::uint64_t>&);
template void octree_keys<double>(const ParticleSet<double>&, const KeyCube&, std::vector<std::uint64_t>&);
template class EssentialTree<float>;
template class EssentialTree<double>;

}  // namespace swirl::gravity
