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
void BarnesHut<Real>::compute(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size) {
  compute_impl(p, out, block_size);
}

template <class Real>
void BarnesHut<Real>::compute_sorted(const ParticleSet<Real>& p, std::span<const std::uint64_t> sorted_keys,
                                     const std::array<double, 3>& corner, double side, GravityField<Real>& out,
                                     std::size_t block_size) {
  if (!uses_linear_tree()) throw std::logic_error("BarnesHut::compute_sorted: only the linear tree is a view of an order");
  if (block_size == 0) throw std::invalid_argument("gravity: block size must be at least 1");
  out.resize(p.size());
  stats_ = GravityStats{};
  const auto t0 = Clock::now();
  linear_.build_sorted(p, sorted_keys, corner, side, linear_settings(), block_size);
  evaluate_linear(p.size(), out, block_size, seconds_since(t0));
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
void BarnesHut<Real>::compute_linear(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size) {
  const auto t0 = Clock::now();
  linear_.build(p, linear_settings(), block_size);
  evaluate_linear(p.size(), out, block_size, seconds_since(t0));
}

template <class Real>
void BarnesHut<Real>::evaluate_linear(std::size_t n, GravityField<Real>& out, std::size_t block_size,
                                      double build_seconds) {
  stats_.tree_build_seconds = build_seconds;
  const auto t1 = Clock::now();
  const WalkCounts counts = linear_.evaluate(out, block_size);
  stats_.force_seconds = seconds_since(t1);
  stats_.trees = 1;
  stats_.nodes = linear_.nodes().size();
  stats_.depth = linear_.depth();
  stats_.leaves = linear_.leaf_count();
  stats_.tree_bytes = linear_.bytes();
  stats_.mean_nodes_visited = n ? double(counts.nodes) / double(n) : 0.0;
  stats_.mean_interactions = n ? double(counts.multipoles + counts.pairs) / double(n) : 0.0;
  work_.assign(1, counts.nodes);
  previous_work_ = work_;
}

template <class Real>
void BarnesHut<Real>::compute_impl(const ParticleSet<Real>& p, GravityField<Real>& out,
                                   std::size_t block_size) {
  if (block_size == 0) throw std::invalid_argument("gravity: block size must be at least 1");
  if (p.size() >= Octree<Real>::npos) throw std::invalid_argument("gravity: too many particles for 32-bit tree indices");
  const std::size_t n = p.size();
  out.resize(n);
  stats_ = GravityStats{};
  if (uses_linear_tree()) return compute_linear(p, out, block_size);

  const auto t0 = Clock::now();
  std::vector<std::uint64_t> weights;
  switch (settings_.scheme) {
    case Scheme::Subdomain:
      build_subdomains(p);
      // Section 4.1.1: the first evaluation deals equal shares of particles,
      // later ones the nodes each sub-domain's tree explored the step before.
      if (previous_work_.size() == sources_.size()) {
        weights = previous_work_;
      } else {
        for (const auto& [b, e] : runs_) weights.push_back(e - b);
      }
      break;
    case Scheme::Subtree:
      build_global_tree(p);
      cut_units();
      // Section 4.2.1: units are dealt by their number of nodes.
      for (const Source& s : sources_) {
        std::uint64_t nodes = 0;
        for (std::uint32_t k = s.entries_begin; k < s.entries_end; ++k) {
          const std::uint32_t e = entries_[k];
          nodes += trees_[0].nodes()[e].end - e;
        }
        weights.push_back(nodes);
      }
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
    walk_sources(p, out, block_size, weights);
    stats_.trees = sources_.size();
  }
  stats_.force_seconds = seconds_since(t1);
  const std::uint64_t visited = std::accumulate(work_.begin(), work_.end(), std::uint64_t(0));
  stats_.mean_nodes_visited = n ? double(visited) / double(n) : 0.0;
  previous_work_ = work_;
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

  // Sub-domains: Morton cells, taken in Morton order, packed greedily into
  // runs of ≤ S particles; a cell with more than S particles is split into its
  // eight children, and one that cannot be split (the finest level) is cut
  // into equal runs. Runs are contiguous in order_.
  const std::size_t S = settings_.subdomain_size;
  runs_.clear();
  std::size_t run_begin = 0;
  std::vector<std::tuple<int, std::size_t, std::size_t>> cells_to_visit{{0, 0, n}};
  while (!cells_to_visit.empty()) {
    const auto [level, b, e] = cells_to_visit.back();
    cells_to_visit.pop_back();
    if (e - b <= S) {
      if (e - run_begin > S) {
        runs_.emplace_back(run_begin, b);
        run_begin = b;
      }
      continue;
    }
    if (level == kMortonLevels) {
      if (run_begin < b) runs_.emplace_back(run_begin, b);
      const std::size_t parts = (e - b + S - 1) / S;
      for (std::size_t q = 0; q < parts; ++q) runs_.emplace_back(b + q * (e - b) / parts, b + (q + 1) * (e - b) / parts);
      run_begin = e;
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
  if (run_begin < n) runs_.emplace_back(run_begin, n);

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
  // U nodes below it cannot lie in one unit: it straddles, and is opened.
  const auto nodes = trees_[0].nodes();
  const std::size_t U = settings_.subtree_nodes;
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
  std::vector<std::uint32_t> visit;
  std::uint64_t count = 0;
  for (const std::uint32_t i : order_) {
    const std::uint32_t leaf = home_tree_[i] == source.tree ? home_leaf_[i] : Octree<Real>::npos;
    const typename Octree<Real>::Target target{p.position.x[i], p.position.y[i], p.position.z[i], i, leaf};
    Accumulator<Real> acc;
    count += tree.walk(entries, target, lambda2, eps2, acc, visit);
    into.acceleration.x[i] = acc.ax;
    into.acceleration.y[i] = acc.ay;
    into.acceleration.z[i] = acc.az;
    into.potential[i] = acc.phi;
  }
  return count;
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
