// The paper's three ways to split the Barnes–Hut work (section 4) and the
// deterministic, load-balanced loops that run them.
#include "swirl/gravity/barnes_hut.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <tuple>

#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Particles per block of a global walk: walks differ in cost, so small blocks balance better.
constexpr std::size_t kWalkBlock = 64;
// Memory for per-tree contributions held at once (each is N × 4 reals).

constexpr int kMortonLevels = 21;  // 3 × 21 = 63 key bits

// Interleaves the bits of three 21-bit cell coordinates, x lowest (the octree's octant numbering).
std::uint64_t morton_key(std::array<std::uint64_t, 3> q) {
  std::uint64_t key = 0;
  for (int bit = 0; bit < kMortonLevels; ++bit)
    for (int a = 0; a < 3; ++a) key |= ((q[std::size_t(a)] >> bit) & 1u) << (3 * bit + a);
  return key;
}

// Deals sources [begin, end) to `bins`, heaviest first, each to the least loaded bin (ties: lower index).
std::vector<std::vector<std::uint32_t>> deal(std::size_t begin, std::size_t end, std::size_t bins,
                                             const std::vector<std::uint64_t>& weight) {
  std::vector<std::uint32_t> sources(end - begin);
  std::iota(sources.begin(), sources.end(), std::uint32_t(begin));
  std::stable_sort(sources.begin(), sources.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return weight[a] > weight[b]; });
  std::vector<std::vector<std::uint32_t>> bin(bins);
  std::vector<std::uint64_t> load(bins, 0);
  for (std::uint32_t s : sources) {
    const auto k = std::size_t(std::min_element(load.begin(), load.end()) - load.begin());
    bin[k].push_back(s);
    load[k] += weight[s];
  }
  return bin;
}

}  // namespace

template <class Real>
BarnesHut<Real>::BarnesHut(const GravitySettings& settings) : settings_(settings) {
  validate(settings_);
}

template <class Real>
void BarnesHut<Real>::compute(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
                              const ActiveSet& active) {
  compute_impl(p, out, block_size, active);
}

template <class Real>
void BarnesHut<Real>::compute_sorted(const ParticleSet<Real>& p, std::span<const std::uint64_t> sorted_keys,
                                     const std::array<double, 3>& corner, double side, GravityField<Real>& out,
                                     std::size_t block_size, const ActiveSet& active) {
  if (!uses_linear_tree()) throw std::logic_error("BarnesHut::compute_sorted: only the linear tree is a view of an order");
  if (block_size == 0) throw std::invalid_argument("gravity: block size must be at least 1");
  out.resize(p.size());
  stats_ = GravityStats{};
  const auto t0 = Clock::now();
  linear_.build_sorted(p, sorted_keys, corner, side, linear_settings(), block_size);
  evaluate_linear(p.size(), out, block_size, seconds_since(t0), active);
}

template <class Real>
LinearTreeSettings BarnesHut<Real>::linear_settings() const {
  LinearTreeSettings ls;
  ls.multipole = settings_.multipole;
  ls.criterion = settings_.criterion;
  ls.opening = settings_.opening;
  ls.softening = settings_.softening;
  ls.bucket_size = settings_.bucket_size;
  ls.walk = settings_.walk;
  ls.group_size = settings_.group_size;
  ls.simd_kernels = settings_.simd;
  return ls;
}

template <class Real>
void BarnesHut<Real>::compute_linear(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
                                     const ActiveSet& active) {
  const auto t0 = Clock::now();
  linear_.build(p, linear_settings(), block_size);
  evaluate_linear(p.size(), out, block_size, seconds_since(t0), active);
}

template <class Real>
void BarnesHut<Real>::evaluate_linear(std::size_t n, GravityField<Real>& out, std::size_t block_size,
                                      double build_seconds, const ActiveSet& active) {
  stats_.tree_build_seconds = build_seconds;
  const auto t1 = Clock::now();
  const WalkCounts counts = linear_.evaluate(out, block_size, active);
  if (!active.all()) {
    n = 0;
    for (std::size_t i = 0; i < out.size(); ++i) n += active.contains(i);
  }
  stats_.walked = n;
  stats_.force_seconds = seconds_since(t1);
  stats_.trees = 1;
  stats_.nodes = linear_.nodes().size();
  stats_.depth = linear_.depth();
  stats_.leaves = linear_.leaf_count();
  stats_.tree_bytes = linear_.bytes();
  stats_.mean_nodes_visited = n ? double(counts.nodes) / double(n) : 0.0;
  stats_.mean_interactions = n ? double(counts.multipoles + counts.pairs) / double(n) : 0.0;
  work_.assign(1, counts.nodes);
}

template <class Real>
void BarnesHut<Real>::compute_impl(const ParticleSet<Real>& p, GravityField<Real>& out,
                                   std::size_t block_size, const ActiveSet& active) {
  if (block_size == 0) throw std::invalid_argument("gravity: block size must be at least 1");
  if (p.size() >= Octree<Real>::npos) throw std::invalid_argument("gravity: too many particles for 32-bit tree indices");
  const std::size_t n = p.size();
  out.resize(n);
  stats_ = GravityStats{};
  stats_.walked = n;
  if (uses_linear_tree()) return compute_linear(p, out, block_size, active);

  const auto t0 = Clock::now();
  weights_.clear();
  switch (settings_.scheme) {
    case Scheme::Subdomain:
      build_subdomains(p);
      subdomain_weights();
      break;
    case Scheme::Subtree:
      build_global_tree(p);
      cut_units();
      unit_weights();
      break;
    case Scheme::Global:
      build_global_tree(p);
      break;
  }
  stats_.tree_build_seconds = seconds_since(t0);
  for (const auto& t : trees_) {
    stats_.nodes += t.nodes().size();
    stats_.depth = std::max(stats_.depth, t.depth());
  }

  const auto t1 = Clock::now();
  if (settings_.scheme == Scheme::Global) {
    walk_global(p, out, block_size);
    stats_.trees = 1;
  } else {
    walk_sources(p, out, block_size, weights_);
    stats_.trees = sources_.size();
  }
  stats_.force_seconds = seconds_since(t1);
  const std::uint64_t visited = std::accumulate(work_.begin(), work_.end(), std::uint64_t(0));
  stats_.mean_nodes_visited = n ? double(visited) / double(n) : 0.0;
  if (settings_.scheme == Scheme::Subdomain) {
    // Section 4.1.1's metric for the next evaluation, kept by sub-domain.
    measured_.clear();
    for (std::size_t t = 0; t < ids_.size(); ++t) measured_.emplace_back(ids_[t], work_[t]);
    std::sort(measured_.begin(), measured_.end());
    measured_work_per_particle_ = stats_.mean_nodes_visited;
  }
}

template <class Real>
void BarnesHut<Real>::subdomain_weights() {
  // Section 4.1.1: the first evaluation deals equal shares of particles, later
  // ones the nodes each sub-domain's tree explored the evaluation before. A
  // sub-domain is found by its cells, so a weight always belongs to the
  // sub-domain it was measured on; a new one is estimated from its particles.
  for (std::size_t t = 0; t < runs_.size(); ++t) {
    const std::uint64_t particles = runs_[t].second - runs_[t].first;
    const auto found = std::lower_bound(measured_.begin(), measured_.end(), ids_[t],
                                        [](const auto& m, const SubdomainId& id) { return m.first < id; });
    if (found != measured_.end() && found->first == ids_[t]) weights_.push_back(found->second);
    else if (!measured_.empty()) weights_.push_back(std::uint64_t(std::llround(measured_work_per_particle_ * double(particles))));
    else weights_.push_back(particles);
  }
}

template <class Real>
void BarnesHut<Real>::unit_weights() {
  // Section 4.2.1: units are dealt by their number of nodes.
  for (const Source& s : sources_) {
    std::uint64_t nodes = 0;
    for (std::uint32_t k = s.entries_begin; k < s.entries_end; ++k) {
      const std::uint32_t e = entries_[k];
      nodes += trees_[0].nodes()[e].end - e;
    }
    weights_.push_back(nodes);
  }
}

template <class Real>
void BarnesHut<Real>::build_subdomains(const ParticleSet<Real>& p) {
  const std::size_t n = p.size();
  // Morton keys of the positions in the bounding cube of all particles.
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::array<double, 3> lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      lo[std::size_t(a)] = std::min(lo[std::size_t(a)], double(p.position[a][i]));
      hi[std::size_t(a)] = std::max(hi[std::size_t(a)], double(p.position[a][i]));
    }
  const double side = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  constexpr double cells = double(std::uint64_t(1) << kMortonLevels);
  const double scale = side > 0 ? cells / side : 0.0;
  keys_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::array<std::uint64_t, 3> q{};
    for (int a = 0; a < 3; ++a) {
      const double c = std::floor((double(p.position[a][i]) - lo[std::size_t(a)]) * scale);
      q[std::size_t(a)] = c >= cells ? std::uint64_t(cells - 1) : (c > 0 ? std::uint64_t(c) : 0);
    }
    keys_[i] = {morton_key(q), std::uint32_t(i)};
  }
  std::sort(keys_.begin(), keys_.end());
  order_.resize(n);
  for (std::size_t k = 0; k < n; ++k) order_[k] = keys_[k].second;

  runs_.clear();
  ids_.clear();
  if (settings_.subdomain_split == SubdomainSplit::Paper) split_paper_cells();
  else split_adaptive();

  // Section 4.1.2: one local tree per sub-domain, built independently.
  const std::size_t trees = runs_.size();
  trees_.resize(trees);
  sources_.resize(trees);
  entries_.assign(trees, 0);  // every walk starts at its tree's root
  home_tree_.resize(n);
  home_leaf_.resize(n);
  parallel::for_blocks("gravity_build_subdomains", trees, 1, [&](std::size_t t, std::size_t, std::size_t) {
    const auto [b, e] = runs_[t];
    const std::span<const std::uint32_t> members(order_.data() + b, e - b);
    trees_[t].build(p, members);
    for (std::size_t s = 0; s < members.size(); ++s) {
      home_tree_[members[s]] = std::uint32_t(t);
      home_leaf_[members[s]] = trees_[t].leaf_of(s);
    }
    sources_[t] = Source{std::uint32_t(t), std::uint32_t(t), std::uint32_t(t + 1)};
  });
}

// Packs whole Morton cells, visited in Morton order, into runs of ≤ S
// particles (keys_ sorted): add(begin, end, key_begin, key_end) offers the next
// cell; cut(...) closes the run and cuts a cell over S into equal runs.
template <class Real>
class BarnesHut<Real>::RunPacker {
 public:
  RunPacker(std::size_t size, std::vector<std::pair<std::size_t, std::size_t>>& runs, std::vector<SubdomainId>& ids)
      : size_(size), runs_(runs), ids_(ids) {}
  void add(std::size_t b, std::size_t e, std::uint64_t key_begin, std::uint64_t key_end) {
    if (e - begin_ > size_) close();
    if (begin_ == end_) {
      begin_ = b;
      key_begin_ = key_begin;
    }
    end_ = e;
    key_end_ = key_end;
  }
  void cut(std::size_t b, std::size_t e, std::uint64_t key_begin, std::uint64_t key_end) {
    close();
    const std::size_t parts = (e - b + size_ - 1) / size_;
    for (std::size_t q = 0; q < parts; ++q) {
      runs_.emplace_back(b + q * (e - b) / parts, b + (q + 1) * (e - b) / parts);
      ids_.push_back({key_begin, key_end, std::uint32_t(q), std::uint32_t(parts)});
    }
    begin_ = end_ = e;
  }
  void close() {
    if (begin_ < end_) {
      runs_.emplace_back(begin_, end_);
      ids_.push_back({key_begin_, key_end_, 0, 1});
    }
    begin_ = end_;
  }

 private:
  std::size_t size_;
  std::vector<std::pair<std::size_t, std::size_t>>& runs_;
  std::vector<SubdomainId>& ids_;
  std::size_t begin_ = 0, end_ = 0;  // the open run
  std::uint64_t key_begin_ = 0, key_end_ = 0;
};

namespace {
// The key range [begin, end) of the level-`level` Morton cell holding `key`.
std::pair<std::uint64_t, std::uint64_t> cell_keys(std::uint64_t key, int level) {
  const int shift = 3 * (kMortonLevels - level);  // ≤ 63
  const std::uint64_t begin = (key >> shift) << shift;
  return {begin, begin + (std::uint64_t(1) << shift)};
}
}  // namespace

template <class Real>
void BarnesHut<Real>::split_adaptive() {
  // Morton cells, taken in Morton order, packed greedily into runs of ≤ S
  // particles; a cell with more than S particles is split into its eight
  // children, and one that cannot be split (the finest level) is cut into
  // equal runs.
  const std::size_t n = keys_.size(), S = settings_.subdomain_size;
  if (n == 0) return;
  RunPacker pack(S, runs_, ids_);
  std::vector<std::tuple<int, std::size_t, std::size_t>> cells_to_visit{{0, 0, n}};
  while (!cells_to_visit.empty()) {
    const auto [level, b, e] = cells_to_visit.back();
    cells_to_visit.pop_back();
    const auto [key_begin, key_end] = cell_keys(keys_[b].first, level);
    if (e - b <= S) {
      pack.add(b, e, key_begin, key_end);
      continue;
    }
    if (level == kMortonLevels) {
      pack.cut(b, e, key_begin, key_end);
      continue;
    }
    const int shift = 3 * (kMortonLevels - 1 - level);
    std::array<std::size_t, 9> bound{};
    bound[0] = b;
    bound[8] = e;
    for (std::uint64_t c = 1; c < 8; ++c)
      bound[c] = std::size_t(std::partition_point(keys_.begin() + std::ptrdiff_t(b), keys_.begin() + std::ptrdiff_t(e),
                                                  [&](const auto& k) { return ((k.first >> shift) & 7u) < c; }) -
                             keys_.begin());
    for (std::size_t c = 8; c-- > 0;)
      if (bound[c] < bound[c + 1]) cells_to_visit.emplace_back(level + 1, bound[c], bound[c + 1]);
  }
  pack.close();
}

template <class Real>
void BarnesHut<Real>::split_paper_cells() {
  // Section 5: "the workspace is initially divided into 512 sub-domains", the
  // level-3 Morton cells of the bounding cube, and sub-domains of at most 208
  // particles are made of them. Ours: the occupied cells in Morton order,
  // packed greedily; the paper does not say what it did with a cell over the
  // size (the centre of a Plummer sphere of 32768 holds thousands): cut into
  // equal runs in Morton order.
  constexpr int kPaperLevel = 3;  // 8³ = 512 cells
  const std::size_t n = keys_.size();
  RunPacker pack(settings_.subdomain_size, runs_, ids_);
  for (std::size_t b = 0; b < n;) {
    const std::pair<std::uint64_t, std::uint64_t> cell = cell_keys(keys_[b].first, kPaperLevel);
    const auto e = std::size_t(std::partition_point(keys_.begin() + std::ptrdiff_t(b), keys_.end(),
                                                    [&](const auto& k) { return k.first < cell.second; }) -
                               keys_.begin());
    if (e - b <= settings_.subdomain_size) pack.add(b, e, cell.first, cell.second);
    else pack.cut(b, e, cell.first, cell.second);
    b = e;
  }
  pack.close();
}

template <class Real>
void BarnesHut<Real>::build_global_tree(const ParticleSet<Real>& p) {
  const std::size_t n = p.size();
  identity_.resize(n);
  std::iota(identity_.begin(), identity_.end(), std::uint32_t(0));
  trees_.resize(1);
  trees_[0].build(p, identity_);  // Fig. 1: inserted one by one, in index order
  home_tree_.assign(n, 0);
  home_leaf_.resize(n);
  for (std::size_t i = 0; i < n; ++i) home_leaf_[i] = trees_[0].leaf_of(i);
  const auto leaves = trees_[0].leaf_particles();
  order_.assign(leaves.begin(), leaves.end());  // walk in leaf order: neighbours walk alike
}

template <class Real>
void BarnesHut<Real>::cut_units() {
  // Section 4.2.1: whole sub-trees packed greedily in depth-first order into
  // units of ≤ U nodes, keeping clusters together first; a node with more than
  // U nodes below it cannot lie in one unit: it straddles units. U is ours
  // (subtree_nodes) or the paper's share of the node total.
  const auto nodes = trees_[0].nodes();
  const std::size_t U = settings_.subtree_split == SubtreeSplit::Parts
                            ? std::max<std::size_t>(1, (nodes.size() + settings_.subtree_parts - 1) / settings_.subtree_parts)
                            : settings_.subtree_nodes;
  unit_nodes_ = U;
  sources_.clear();
  entries_.clear();
  std::size_t fill = 0, unit_begin = 0;
  std::vector<std::uint32_t> stack;
  if (!nodes.empty()) stack.push_back(0);
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    const std::size_t size = nodes[node].end - node;
    if (size <= U) {
      if (fill + size > U) {
        sources_.push_back({0, std::uint32_t(unit_begin), std::uint32_t(entries_.size())});
        unit_begin = entries_.size();
        fill = 0;
      }
      entries_.push_back(node);
      fill += size;
    } else {
      std::vector<std::uint32_t> children;
      for (std::uint32_t c = node + 1; c < nodes[node].end; c = nodes[c].end) children.push_back(c);
      stack.insert(stack.end(), children.rbegin(), children.rend());
    }
  }
  if (unit_begin < entries_.size()) sources_.push_back({0, std::uint32_t(unit_begin), std::uint32_t(entries_.size())});

  // The units below every entry and straddling node. Units are runs of
  // entries in depth-first order, so those below a node are a range; a
  // straddling node's children are entries or straddle, and come after it.
  unit_first_.assign(nodes.size(), 0);
  unit_last_.assign(nodes.size(), 0);
  for (std::uint32_t u = 0; u < sources_.size(); ++u)
    for (std::uint32_t k = sources_[u].entries_begin; k < sources_[u].entries_end; ++k)
      unit_first_[entries_[k]] = unit_last_[entries_[k]] = u;
  for (std::size_t node = nodes.size(); node-- > 0;) {
    if (nodes[node].end - node <= U) continue;
    const std::uint32_t first_child = std::uint32_t(node + 1);
    unit_first_[node] = unit_first_[first_child];
    for (std::uint32_t c = first_child; c < nodes[node].end; c = nodes[c].end) unit_last_[node] = unit_last_[c];
  }
}

template <class Real>
void BarnesHut<Real>::walk_global(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size) {
  const Octree<Real>& tree = trees_[0];
  const Real lambda2 = Real(settings_.opening * settings_.opening);
  const Real eps2 = Real(settings_.softening * settings_.softening);
  const std::uint32_t root = 0;
  const std::uint64_t visited = parallel::reduce_blocks(
      "gravity_walk_global", p.size(), std::min(block_size, kWalkBlock), std::uint64_t(0),
      [&](std::size_t b, std::size_t e) {
        std::vector<std::uint32_t> visit;
        std::uint64_t count = 0;
        for (std::size_t k = b; k < e; ++k) {
          const std::uint32_t i = order_[k];
          const typename Octree<Real>::Target target{p.position.x[i], p.position.y[i], p.position.z[i], i, home_leaf_[i]};
          Accumulator<Real> acc;
          count += tree.walk({&root, 1}, target, lambda2, eps2, acc, visit);
          out.acceleration.x[i] = acc.ax;
          out.acceleration.y[i] = acc.ay;
          out.acceleration.z[i] = acc.az;
          out.potential[i] = acc.phi;
        }
        return count;
      },
      [](std::uint64_t a, std::uint64_t b) { return a + b; });
  work_.assign(1, visited);
}

template <class Real>
std::uint64_t BarnesHut<Real>::walk_source(const ParticleSet<Real>& p, std::size_t s, GravityField<Real>& into) const {
  const Source& source = sources_[s];
  const Octree<Real>& tree = trees_[source.tree];
  const std::span<const std::uint32_t> entries(entries_.data() + source.entries_begin,
                                               source.entries_end - source.entries_begin);
  const Real lambda2 = Real(settings_.opening * settings_.opening);
  const Real eps2 = Real(settings_.softening * settings_.softening);
  // The paper's replicated upper levels, when the tree has any (a one-unit
  // tree's root is the unit's only entry).
  const bool upper = settings_.scheme == Scheme::Subtree && settings_.upper_nodes == UpperNodes::Clusters &&
                     tree.nodes().size() > unit_nodes_;
  std::vector<std::uint32_t> visit, walked;
  std::uint64_t count = 0;
  for (const std::uint32_t i : order_) {
    const std::uint32_t leaf = home_tree_[i] == source.tree ? home_leaf_[i] : Octree<Real>::npos;
    const typename Octree<Real>::Target target{p.position.x[i], p.position.y[i], p.position.z[i], i, leaf};
    Accumulator<Real> acc;
    if (upper) count += walk_upper(std::uint32_t(s), target, lambda2, eps2, acc, visit, walked);
    else count += tree.walk(entries, target, lambda2, eps2, acc, visit);
    into.acceleration.x[i] = acc.ax;
    into.acceleration.y[i] = acc.ay;
    into.acceleration.z[i] = acc.az;
    into.potential[i] = acc.phi;
  }
  return count;
}

template <class Real>
std::uint64_t BarnesHut<Real>::walk_upper(std::uint32_t unit, const typename Octree<Real>::Target& target,
                                          Real lambda2, Real eps2, Accumulator<Real>& acc,
                                          std::vector<std::uint32_t>& visit, std::vector<std::uint32_t>& entries) const {
  // From the root down the straddling nodes above this unit's entries: a node
  // the λ rule accepts is one cluster, added by the unit holding its first
  // descendant only (the other units' share of its mass is in it); one it
  // opens leads to the children holding this unit's entries. The entries the
  // walk reaches are then walked as in the global tree, in the order reached.
  const Octree<Real>& tree = trees_[0];
  const auto nodes = tree.nodes();
  std::uint64_t count = 0;
  entries.clear();
  visit.assign(1, 0);
  while (!visit.empty()) {
    const std::uint32_t n = visit.back();
    visit.pop_back();
    ++count;
    if (tree.accepts(n, target, lambda2)) {
      const auto& node = nodes[n];
      if (unit_first_[n] == unit) acc.add(node.x - target.x, node.y - target.y, node.z - target.z, node.mass, eps2);
      continue;
    }
    const std::size_t first_visit = visit.size();
    for (std::uint32_t c = n + 1; c < nodes[n].end; c = nodes[c].end) {
      if (unit < unit_first_[c] || unit > unit_last_[c]) continue;
      if (nodes[c].end - c > unit_nodes_) visit.push_back(c);
      else entries.push_back(c);
    }
    std::reverse(visit.begin() + std::ptrdiff_t(first_visit), visit.end());  // children in depth-first order
  }
  return count + tree.walk(entries, target, lambda2, eps2, acc, visit);
}

template <class Real>
void BarnesHut<Real>::walk_sources(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
                                   const std::vector<std::uint64_t>& weights) {
  const std::size_t n = p.size(), sources = sources_.size();
  const std::size_t bins = std::size_t(parallel::thread_count());
  // The paper balances all trees at once (heaviest first to the least loaded
  // SPE). Here each tree's contribution is a field of n particles, summed into
  // the result in tree order so that the sum is the same for any thread count;
  // the deal covers as many trees as the buffer budget holds at once (all of
  // them when it holds them, e.g. 51 trees of 8192 particles), and at least
  // one per thread.
  const std::size_t affordable = buffer_bytes_ / std::max<std::size_t>(1, 4 * n * sizeof(Real));
  const std::size_t chunk = std::max<std::size_t>(1, std::min(sources, std::max(bins, affordable)));
  buffers_.resize(chunk);
  for (auto& b : buffers_) b.resize(n);
  for (int a = 0; a < 3; ++a) std::fill(out.acceleration[a].begin(), out.acceleration[a].end(), Real(0));
  std::fill(out.potential.begin(), out.potential.end(), Real(0));
  work_.assign(sources, 0);

  for (std::size_t c0 = 0; c0 < sources; c0 += chunk) {
    const std::size_t c1 = std::min(sources, c0 + chunk);
    const auto bin = deal(c0, c1, bins, weights);
    parallel::for_blocks("gravity_walk_trees", bins, 1, [&](std::size_t k, std::size_t, std::size_t) {
      for (std::uint32_t s : bin[k]) work_[s] = walk_source(p, s, buffers_[s - c0]);
    });
    // Section 4.1.3: the force on a particle is the sum over trees, in tree order.
    parallel::for_blocks("gravity_sum_trees", n, block_size, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t s = c0; s < c1; ++s) {
        const GravityField<Real>& f = buffers_[s - c0];
        for (int a = 0; a < 3; ++a) {
          Real* acc = out.acceleration[a].data();
          const Real* add = f.acceleration[a].data();
#pragma omp simd
          for (std::size_t i = b; i < e; ++i) acc[i] += add[i];
        }
        Real* phi = out.potential.data();
        const Real* add = f.potential.data();
#pragma omp simd
        for (std::size_t i = b; i < e; ++i) phi[i] += add[i];
      }
    });
  }
}

template class BarnesHut<float>;
template class BarnesHut<double>;

}  // namespace swirl::gravity
