// The fast multipole method (fmm.hpp): expansion tables, the upward pass
// (P2M, M2M), the dual tree walk, the mutual M2L and P2P in chunks, and the
// downward pass (L2L, L2P). Formulas and the determinism argument: fmm.hpp.
#include "swirl/gravity/fmm.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "swirl/core/morton.hpp"
#include "swirl/gravity/pair_law.hpp"
#include "swirl/parallel/for_blocks.hpp"

namespace swirl::gravity {

namespace {

// ---------------------------------------------------------------------------
// Multi-index tables, all built at compile time for an order.

// Multi-indices of total order ≤ q: (q + 1)(q + 2)(q + 3) / 6.
constexpr int coef_count(int q) { return q < 0 ? 0 : (q + 1) * (q + 2) * (q + 3) / 6; }

// Multi-indices n of total order ≤ Q, numbered by order, then n_x and n_y
// descending: the numbering of order ≤ P is a prefix of that of order ≤ Q, so
// multipoles (order p) and local coefficients (order p + 1) share it.
template <int Q>
struct MultiIndex {
  static constexpr int K = coef_count(Q);
  std::array<std::array<int, 3>, K> n{};
  std::array<int, (Q + 1) * (Q + 1) * (Q + 1)> lookup{};
  constexpr MultiIndex() {
    for (auto& v : lookup) v = -1;
    int s = 0;
    for (int q = 0; q <= Q; ++q)
      for (int i = q; i >= 0; --i)
        for (int j = q - i; j >= 0; --j) {
          n[std::size_t(s)] = {i, j, q - i - j};
          lookup[std::size_t((i * (Q + 1) + j) * (Q + 1) + (q - i - j))] = s;
          ++s;
        }
  }
  constexpr int at(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i + j + k > Q) return -1;
    return lookup[std::size_t((i * (Q + 1) + j) * (Q + 1) + k)];
  }
  constexpr int order(int s) const {
    const auto& m = n[std::size_t(s)];
    return m[0] + m[1] + m[2];
  }
};

// T_m = t^m / m! from T_{m − e_a} · t_a / m_a, a the first non-zero axis of m.
struct PowerStep {
  int parent = 0, axis = 0;
  double inv = 0;
};
template <int Q>
constexpr std::array<PowerStep, std::size_t(coef_count(Q))> make_powers() {
  constexpr MultiIndex<Q> mi{};
  std::array<PowerStep, std::size_t(coef_count(Q))> out{};
  for (int s = 1; s < coef_count(Q); ++s) {
    const auto m = mi.n[std::size_t(s)];
    const int a = m[0] > 0 ? 0 : (m[1] > 0 ? 1 : 2);
    auto parent = m;
    --parent[std::size_t(a)];
    out[std::size_t(s)] = {mi.at(parent[0], parent[1], parent[2]), a, 1.0 / double(m[std::size_t(a)])};
  }
  return out;
}

// The recurrence for D_m = ∂^m g (fmm.hpp):
//   D_m = [Σ_a c1_a R_a D_{m−e_a} + Σ_a c2_a D_{m−2e_a}] / ρ²,
//   c1_a = −(2|m| − 1) m_a / |m|,  c2_a = −(|m| − 1) m_a (m_a − 1) / |m|  (−1: absent).
struct RecurrenceStep {
  std::array<int, 3> first{-1, -1, -1}, second{-1, -1, -1};
  std::array<double, 3> c1{}, c2{};
};
template <int Q>
constexpr std::array<RecurrenceStep, std::size_t(coef_count(Q))> make_recurrence() {
  constexpr MultiIndex<Q> mi{};
  std::array<RecurrenceStep, std::size_t(coef_count(Q))> out{};
  for (int s = 1; s < coef_count(Q); ++s) {
    const auto m = mi.n[std::size_t(s)];
    const double order = double(mi.order(s));
    RecurrenceStep r;
    for (std::size_t a = 0; a < 3; ++a) {
      if (m[a] >= 1) {
        auto d = m;
        --d[a];
        r.first[a] = mi.at(d[0], d[1], d[2]);
        r.c1[a] = -(2 * order - 1) * double(m[a]) / order;
      }
      if (m[a] >= 2) {
        auto d = m;
        d[a] -= 2;
        r.second[a] = mi.at(d[0], d[1], d[2]);
        r.c2[a] = -(order - 1) * double(m[a]) * double(m[a] - 1) / order;
      }
    }
    out[std::size_t(s)] = r;
  }
  return out;
}

// out[o] += factor · in[i] · other[t]: one term of a contraction.
struct Term {
  int out = 0, in = 0, other = 0;
  double factor = 1;
};

// M2L: C_k += (−1)^{|n|} M_n D_{k+n} over |n| ≤ P, |k| + |n| ≤ P + 1.
template <int P>
constexpr int m2l_count() {
  constexpr MultiIndex<P + 1> mi{};
  int c = 0;
  for (int k = 0; k < coef_count(P + 1); ++k)
    for (int n = 0; n < coef_count(P); ++n) c += mi.order(k) + mi.order(n) <= P + 1 ? 1 : 0;
  return c;
}
template <int P>
constexpr std::array<Term, std::size_t(m2l_count<P>())> make_m2l() {
  constexpr MultiIndex<P + 1> mi{};
  std::array<Term, std::size_t(m2l_count<P>())> out{};
  std::size_t c = 0;
  for (int k = 0; k < coef_count(P + 1); ++k)
    for (int n = 0; n < coef_count(P); ++n) {
      if (mi.order(k) + mi.order(n) > P + 1) continue;
      const auto a = mi.n[std::size_t(k)], b = mi.n[std::size_t(n)];
      out[c++] = {k, n, mi.at(a[0] + b[0], a[1] + b[1], a[2] + b[2]), mi.order(n) % 2 ? -1.0 : 1.0};
    }
  return out;
}

// Shifts by the binomial theorem: out_j += in_k T_{k−j}(d) for j ≤ k
// (componentwise), |k| ≤ Q. M2M: parent M_k += child M_j T_{k−j}(z_c − z) is
// the same sum with the roles named the other way; both tables list (out, in, other).
template <int Q>
constexpr int shift_count() {
  constexpr MultiIndex<Q> mi{};
  int c = 0;
  for (int k = 0; k < coef_count(Q); ++k)
    for (int j = 0; j < coef_count(Q); ++j) {
      const auto a = mi.n[std::size_t(k)], b = mi.n[std::size_t(j)];
      c += (b[0] <= a[0] && b[1] <= a[1] && b[2] <= a[2]) ? 1 : 0;
    }
  return c;
}
// down = true (L2L): out = j, in = k; false (M2M): out = k, in = j.
template <int Q, bool down>
constexpr std::array<Term, std::size_t(shift_count<Q>())> make_shift() {
  constexpr MultiIndex<Q> mi{};
  std::array<Term, std::size_t(shift_count<Q>())> out{};
  std::size_t c = 0;
  for (int k = 0; k < coef_count(Q); ++k)
    for (int j = 0; j < coef_count(Q); ++j) {
      const auto a = mi.n[std::size_t(k)], b = mi.n[std::size_t(j)];
      if (!(b[0] <= a[0] && b[1] <= a[1] && b[2] <= a[2])) continue;
      const int diff = mi.at(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
      out[c++] = down ? Term{j, k, diff, 1.0} : Term{k, j, diff, 1.0};
    }
  return out;
}

// The gradient of the local polynomial: index of k + e_a for |k| ≤ P.
template <int P>
constexpr std::array<std::array<int, 3>, std::size_t(coef_count(P))> make_gradient() {
  constexpr MultiIndex<P + 1> mi{};
  std::array<std::array<int, 3>, std::size_t(coef_count(P))> out{};
  for (int k = 0; k < coef_count(P); ++k) {
    const auto a = mi.n[std::size_t(k)];
    out[std::size_t(k)] = {mi.at(a[0] + 1, a[1], a[2]), mi.at(a[0], a[1] + 1, a[2]), mi.at(a[0], a[1], a[2] + 1)};
  }
  return out;
}

template <int Q>
constexpr std::array<double, std::size_t(coef_count(Q))> make_parity() {
  constexpr MultiIndex<Q> mi{};
  std::array<double, std::size_t(coef_count(Q))> out{};
  for (int k = 0; k < coef_count(Q); ++k) out[std::size_t(k)] = mi.order(k) % 2 ? -1.0 : 1.0;
  return out;
}

// Everything the kernels of order p use.
template <int P>
struct Order {
  static constexpr int Q = P + 1;
  static constexpr std::size_t KM = std::size_t(coef_count(P));  // multipoles
  static constexpr std::size_t KL = std::size_t(coef_count(Q));  // local coefficients, derivatives
  static constexpr auto powers = make_powers<Q>();
  static constexpr auto recurrence = make_recurrence<Q>();
  static constexpr auto m2l = make_m2l<P>();
  static constexpr auto m2m = make_shift<P, false>();
  static constexpr auto l2l = make_shift<Q, true>();
  static constexpr auto gradient = make_gradient<P>();
  static constexpr auto parity = make_parity<Q>();
  // A cell pair with at most this many particle pairs is summed directly
  // (exact, and cheaper): the cost of one M2L (eight pairs per vector) in
  // mutual pair terms, modelled as 10 units per derivative and 4 per
  // contraction term against 75 per pair term; 6, 15, 30, 58 for p = 2..5.
  // The 75 was timed (N = 65536, θ = 0.7, bucket 32, p = 3 and 5): 75 and 150
  // equal, 15 % faster than 30.
  static constexpr std::uint64_t direct_pairs = (10 * KL + 4 * m2l.size()) / 75;
};

// T_m = t^m / m! for all m of order ≤ Q (T has coef_count(Q) entries).
template <int Q>
inline void powers(double x, double y, double z, double* T) {
  constexpr auto steps = make_powers<Q>();
  const double t[3] = {x, y, z};
  T[0] = 1;
  for (std::size_t s = 1; s < steps.size(); ++s)
    T[s] = T[steps[s].parent] * t[steps[s].axis] * steps[s].inv;
}

// Nodes per block of the level-by-level passes; a level of one block runs on
// the calling thread (as in linear_octree.cpp). The same blocks either way.
constexpr std::size_t kNodeBlock = 256;
template <class Body>
void node_blocks(std::string_view kernel, std::size_t n, Body&& body) {
  if (n <= kNodeBlock) {
    if (n > 0) body(std::size_t(0), n, std::size_t(0));
    return;
  }
  parallel::for_blocks(kernel, n, kNodeBlock, std::forward<Body>(body));
}

// The walk is cut into at least this many tasks (a fixed number: the tasks,
// hence the lists, never depend on the thread count).
constexpr std::size_t kWalkTasks = 256;
// M2L interactions per chunk (buffer: 2 × coef_count(p + 1) doubles each:
// 1.4 MB at p = 5, so that the add pass finds it still in cache). With 4096
// (5.5 MB) the M2L at 2²⁰ particles was bound by memory: 0.57 s on one
// thread and on two; with 1024 0.32 s on two (docs/performance/gravity-peers.md).
// The chunking does not change a result: every cell receives its terms in list order.
constexpr std::size_t kM2lChunk = 1024;
// The P2P's inner loops run over whole vectors of this many doubles (one
// AVX-512 or two AVX2 registers): a fixed trip count the compiler vectorizes
// without a scalar remainder, each lane its own partial sums.
constexpr std::size_t kLanes = 8;
// The lanes' partial sums, added in a fixed order.
inline double lane_sum(const double* v) {
  return ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7]));
}
// P2P buffer per chunk, doubles (a chunk holds at least one interaction).
constexpr std::size_t kP2pBudget = std::size_t(1) << 18;

// The M2L of kLanes pairs at once, lane l being pair l: the same operations
// on every lane (so a pair's result does not depend on its lane), in
// fixed-trip-count loops the compiler vectorizes across the pairs. Both
// kernels are unrolled at compile time (a fold over the table indices): every
// index and coefficient is a constant, so the compiler emits straight-line
// vector multiply-adds instead of a loop reading the table.
using Lanes = double[kLanes];

template <int Q, std::size_t s>
[[gnu::always_inline]] inline void recurrence_lanes(const Lanes* R, const Lanes& inv2, Lanes* D) {
  constexpr RecurrenceStep r = make_recurrence<Q>()[s];
#pragma omp simd
  for (std::size_t l = 0; l < kLanes; ++l) {
    double sum = 0;
    if constexpr (r.first[0] >= 0) sum += r.c1[0] * R[0][l] * D[r.first[0]][l];
    if constexpr (r.first[1] >= 0) sum += r.c1[1] * R[1][l] * D[r.first[1]][l];
    if constexpr (r.first[2] >= 0) sum += r.c1[2] * R[2][l] * D[r.first[2]][l];
    if constexpr (r.second[0] >= 0) sum += r.c2[0] * D[r.second[0]][l];
    if constexpr (r.second[1] >= 0) sum += r.c2[1] * D[r.second[1]][l];
    if constexpr (r.second[2] >= 0) sum += r.c2[2] * D[r.second[2]][l];
    D[s][l] = sum * inv2[l];
  }
}
template <int Q, std::size_t... S>
[[gnu::always_inline]] inline void derivatives_lanes(const Lanes* R, const Lanes& inv2, Lanes* D,
                                                     std::index_sequence<S...>) {
  // The comma fold runs left to right: D_s only reads lower orders, already written.
  (recurrence_lanes<Q, S + 1>(R, inv2, D), ...);
}

template <int P, std::size_t I>
[[gnu::always_inline]] inline void contract_lanes_term(const Lanes* Ma, const Lanes* Mb, const Lanes* D, Lanes* ca,
                                                       Lanes* cb) {
  constexpr Term t = Order<P>::m2l[I];
#pragma omp simd
  for (std::size_t l = 0; l < kLanes; ++l) {
    ca[t.out][l] += t.factor * Mb[t.in][l] * D[t.other][l];
    cb[t.out][l] += Ma[t.in][l] * D[t.other][l];
  }
}
// Terms per fold expression: clang caps a fold's nesting at 256.
constexpr std::size_t kFold = 128;
template <int P, std::size_t base, std::size_t... I>
[[gnu::always_inline]] inline void contract_fold(const Lanes* Ma, const Lanes* Mb, const Lanes* D, Lanes* ca, Lanes* cb,
                                                 std::index_sequence<I...>) {
  (contract_lanes_term<P, base + I>(Ma, Mb, D, ca, cb), ...);
}
template <int P, std::size_t... G>
[[gnu::always_inline]] inline void contract_folds(const Lanes* Ma, const Lanes* Mb, const Lanes* D, Lanes* ca,
                                                  Lanes* cb, std::index_sequence<G...>) {
  constexpr std::size_t n = Order<P>::m2l.size();
  (contract_fold<P, G * kFold>(Ma, Mb, D, ca, cb, std::make_index_sequence<std::min(kFold, n - G * kFold)>()), ...);
}
// C_k(A) += (−1)^{|n|} M_n(B) D_{k+n},  C_k(B) += M_n(A) D_{k+n} (the parity (−1)^{|k|} applied by the caller),
// in table order.
template <int P>
[[gnu::always_inline]] inline void contract_lanes(const Lanes* Ma, const Lanes* Mb, const Lanes* D, Lanes* ca,
                                                  Lanes* cb) {
  constexpr std::size_t n = Order<P>::m2l.size();
  contract_folds<P>(Ma, Mb, D, ca, cb, std::make_index_sequence<(n + kFold - 1) / kFold>());
}

// The mutual M2L of the pairs (ia[l], ib[l]), l < kLanes: out + l·2K holds
// C(A) then C(B) of lane l (K = coef_count(p + 1)) for l < valid. A free
// function of the order alone (not of the particles' type): compiled once per p.
template <int P>
void m2l_lanes(const std::array<std::uint32_t, kLanes>& ia, const std::array<std::uint32_t, kLanes>& ib,
               const double* zx, const double* zy, const double* zz, const double* multipoles, double eps2,
               double* out, std::size_t valid) {
  using O = Order<P>;
  alignas(64) Lanes R[3], inv2, D[O::KL], Ma[O::KM], Mb[O::KM], ca[O::KL], cb[O::KL];
  for (std::size_t l = 0; l < kLanes; ++l) {
    const std::size_t a = ia[l], b = ib[l];
    R[0][l] = zx[a] - zx[b];
    R[1][l] = zy[a] - zy[b];
    R[2][l] = zz[a] - zz[b];
    for (std::size_t k = 0; k < O::KM; ++k) {
      Ma[k][l] = multipoles[a * O::KM + k];
      Mb[k][l] = multipoles[b * O::KM + k];
    }
  }
  // D_m(z_A − z_B), once for both directions (fmm.hpp).
#pragma omp simd
  for (std::size_t l = 0; l < kLanes; ++l) {
    inv2[l] = 1.0 / (R[0][l] * R[0][l] + R[1][l] * R[1][l] + R[2][l] * R[2][l] + eps2);
    D[0][l] = std::sqrt(inv2[l]);
  }
  derivatives_lanes<O::Q>(R, inv2, D, std::make_index_sequence<O::KL - 1>());
  for (std::size_t k = 0; k < O::KL; ++k)
    for (std::size_t l = 0; l < kLanes; ++l) ca[k][l] = cb[k][l] = 0;
  contract_lanes<P>(Ma, Mb, D, ca, cb);
  for (std::size_t l = 0; l < valid; ++l) {
    double* o = out + l * 2 * O::KL;
    for (std::size_t k = 0; k < O::KL; ++k) {
      o[k] = ca[k][l];
      o[O::KL + k] = O::parity[k] * cb[k][l];
    }
  }
}

// Owner ranges for adding a chunk's buffers: any number gives the same sums
// (each owner's terms are added in list order); more than the threads balance.
std::size_t owner_ranges() { return std::size_t(4 * parallel::thread_count()); }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void validate(const FmmSettings& s) {
  if (!(s.order >= 2 && s.order <= 5))
    throw std::invalid_argument(fmt::format("fmm: expansion order p = {} is outside [2, 5]", s.order));
  if (!(s.opening >= 0 && s.opening <= 1))
    throw std::invalid_argument(
        fmt::format("fmm: opening angle theta = {} is outside [0, 1] (cells interact iff r_A + r_B < theta |z_A - z_B|)",
                    s.opening));
  if (!(s.softening >= 0 && std::isfinite(s.softening)))
    throw std::invalid_argument(fmt::format("fmm: softening epsilon = {} must be finite and >= 0", s.softening));
  if (s.bucket_size < 1) throw std::invalid_argument("fmm: bucket size must be at least 1 particle");
}

template <class Real>
Fmm<Real>::Fmm(const FmmSettings& settings) : settings_(settings) {
  validate(settings_);
}

template <class Real>
LinearTreeSettings Fmm<Real>::tree_settings() const {
  LinearTreeSettings t;
  t.opening = settings_.opening;
  t.softening = settings_.softening;
  t.bucket_size = settings_.bucket_size;
  return t;
}

template <class Real>
void Fmm<Real>::compute(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
                        const ActiveSet& active) {
  const auto t0 = std::chrono::steady_clock::now();
  tree_.build(p, tree_settings(), block_size);
  evaluate_order(out, block_size, seconds_since(t0), active);
}

// active_cell_ from the particles' flags: a node's particles are the sorted
// slots [begin, end), so one prefix count over the slots answers every node.
template <class Real>
void Fmm<Real>::mark_active_cells(const ActiveSet& active) {
  const std::size_t n = tree_.x().size();
  if (active.all()) {
    active_cell_.clear();
    stats_.active = n;
    return;
  }
  const auto order = tree_.order();
  std::vector<std::uint64_t>& before = active_before_;  // active slots before slot s
  before.resize(n + 1);
  before[0] = 0;
  for (std::size_t s = 0; s < n; ++s) before[s + 1] = before[s] + (active.contains(order[s]) ? 1u : 0u);
  stats_.active = before[n];
  const LinearNodes<Real>& t = tree_.nodes();
  active_cell_.resize(t.size());
  for (std::size_t c = 0; c < t.size(); ++c) active_cell_[c] = before[t.end[c]] > before[t.begin[c]] ? 1 : 0;
}

// The expansion order is a template parameter (the M2L tables unroll at compile time).
template <class Real>
void Fmm<Real>::evaluate_order(GravityField<Real>& out, std::size_t block_size, double tree_seconds,
                               const ActiveSet& active) {
  stats_ = FmmStats{};
  stats_.tree_seconds = tree_seconds;
  mark_active_cells(active);
  switch (settings_.order) {
    case 2: evaluate<2>(out, block_size); break;
    case 3: evaluate<3>(out, block_size); break;
    case 4: evaluate<4>(out, block_size); break;
    default: evaluate<5>(out, block_size); break;
  }
}

template <class Real>
void Fmm<Real>::compute_sorted(const ParticleSet<Real>& p, std::span<const std::uint64_t> sorted_keys,
                               const std::array<double, 3>& corner, double side, GravityField<Real>& out,
                               std::size_t block_size, const ActiveSet& active) {
  const auto t0 = std::chrono::steady_clock::now();
  tree_.build_sorted(p, sorted_keys, corner, side, tree_settings(), block_size);
  evaluate_order(out, block_size, seconds_since(t0), active);
}

template <class Real>
template <int P>
void Fmm<Real>::evaluate(GravityField<Real>& out, std::size_t block_size) {
  using O = Order<P>;
  const std::size_t n = tree_.x().size();
  const std::size_t nodes = tree_.nodes().size();
  out.resize(n);
  stats_.nodes = nodes;
  stats_.leaves = tree_.leaf_count();
  stats_.depth = tree_.depth();
  if (n == 0) return;

  auto t0 = std::chrono::steady_clock::now();
  upward<P>();
  stats_.upward_seconds = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  walk(O::direct_pairs);
  stats_.walk_seconds = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  locals_.assign(nodes * O::KL, 0.0);
  interact_m2l<P>();
  stats_.m2l_seconds = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  for (auto* v : {&ax_, &ay_, &az_, &phi_}) v->assign(n, 0.0);
  interact_p2p();
  stats_.p2p_seconds = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  downward<P>(out, block_size);
  stats_.downward_seconds = seconds_since(t0);

  stats_.bytes = tree_.bytes() +
                 sizeof(double) * (zx_.size() * 5 + multipoles_.size() + locals_.size() + 4 * ax_.size() +
                                   buffer_.capacity()) +
                 sizeof(Pair) * (m2l_.capacity() + p2p_.capacity()) + active_cell_.capacity() +
                 sizeof(std::uint64_t) * active_before_.capacity();
}

// Centres of mass, radii and multipoles, deepest level first; each node is
// written by one block and reads only its particles or its children.
template <class Real>
template <int P>
void Fmm<Real>::upward() {
  using O = Order<P>;
  const LinearNodes<Real>& t = tree_.nodes();
  const std::size_t count = t.size();
  for (auto* v : {&zx_, &zy_, &zz_, &mass_, &radius_}) v->assign(count, 0.0);
  multipoles_.assign(count * O::KM, 0.0);
  const int depth = tree_.depth();
  level_start_.assign(std::size_t(depth) + 2, count);
  for (std::size_t node = count; node-- > 0;) level_start_[t.level[node]] = node;
  const auto x = tree_.x(), y = tree_.y(), z = tree_.z(), m = tree_.m();
  const auto corner = tree_.root_corner();
  const double side = tree_.root_side();

  for (int level = depth; level >= 0; --level) {
    const std::size_t lb = level_start_[std::size_t(level)], le = level_start_[std::size_t(level) + 1];
    node_blocks("fmm_upward", le - lb, [&](std::size_t b, std::size_t e, std::size_t) {
      double T[O::KL];
      for (std::size_t node = lb + b; node < lb + e; ++node) {
        const double cell = side / double(std::uint64_t(1) << t.level[node]);
        const std::uint64_t prefix = t.prefix[node];
        const double lo[3] = {corner[0] + double(morton_compact(prefix)) * cell,
                              corner[1] + double(morton_compact(prefix >> 1)) * cell,
                              corner[2] + double(morton_compact(prefix >> 2)) * cell};
        double* M = &multipoles_[node * O::KM];
        double mass = 0, cx = 0, cy = 0, cz = 0;
        const std::uint32_t first = t.begin[node], last = t.end[node];
        const bool leaf = t.child_count[node] == 0;
        if (leaf) {
          for (std::uint32_t s = first; s < last; ++s) {
            const double ms = double(m[s]);
            mass += ms;
            cx += ms * double(x[s]);
            cy += ms * double(y[s]);
            cz += ms * double(z[s]);
          }
        } else {
          for (std::uint32_t c = t.first_child[node]; c < t.first_child[node] + t.child_count[node]; ++c) {
            mass += mass_[c];
            cx += mass_[c] * zx_[c];
            cy += mass_[c] * zy_[c];
            cz += mass_[c] * zz_[c];
          }
        }
        if (leaf && last - first == 1) {  // exactly the particle
          cx = double(x[first]);
          cy = double(y[first]);
          cz = double(z[first]);
        } else if (mass != 0) {
          cx /= mass;
          cy /= mass;
          cz /= mass;
        } else {  // massless: the cube's centre
          cx = lo[0] + 0.5 * cell;
          cy = lo[1] + 0.5 * cell;
          cz = lo[2] + 0.5 * cell;
        }
        double radius = 0;
        if (leaf) {
          // P2M: M_n = Σ m s^n / n!, and the exact radius.
          double r2 = 0;
          for (std::uint32_t s = first; s < last; ++s) {
            const double dx = double(x[s]) - cx, dy = double(y[s]) - cy, dz = double(z[s]) - cz;
            r2 = std::max(r2, dx * dx + dy * dy + dz * dz);
            powers<P>(dx, dy, dz, T);
            const double ms = double(m[s]);
            for (std::size_t k = 0; k < O::KM; ++k) M[k] += ms * T[k];
          }
          radius = std::sqrt(r2);
        } else {
          // M2M: M_k += M_j(child) T_{k−j}(z_c − z); the radius bound through the children.
          for (std::uint32_t c = t.first_child[node]; c < t.first_child[node] + t.child_count[node]; ++c) {
            const double dx = zx_[c] - cx, dy = zy_[c] - cy, dz = zz_[c] - cz;
            radius = std::max(radius, std::sqrt(dx * dx + dy * dy + dz * dz) + radius_[c]);
            powers<P>(dx, dy, dz, T);
            const double* Mc = &multipoles_[std::size_t(c) * O::KM];
            for (const Term& term : O::m2m) M[term.out] += Mc[term.in] * T[term.other];
          }
          // Every particle is inside the cube: the farthest corner bounds the radius too.
          double corner2 = 0;
          const double zc[3] = {cx, cy, cz};
          for (int a = 0; a < 3; ++a) {
            const double far = std::max(zc[a] - lo[a], lo[a] + cell - zc[a]);
            corner2 += far * far;
          }
          radius = std::min(radius, std::sqrt(corner2));
        }
        zx_[node] = cx;
        zy_[node] = cy;
        zz_[node] = cz;
        mass_[node] = mass;
        radius_[node] = radius;
      }
    });
  }
}

// The dual tree walk (fmm.hpp): seeds serially, then walks the tasks in
// parallel, each into its own lists, concatenated in task order.
template <class Real>
void Fmm<Real>::walk(std::uint64_t direct_pairs) {
  const LinearNodes<Real>& t = tree_.nodes();
  const double theta = settings_.opening;
  enum class Action { M2L, P2P, Split };
  const auto size = [&](std::uint32_t c) { return std::uint64_t(t.end[c] - t.begin[c]); };
  const auto leaf = [&](std::uint32_t c) { return t.child_count[c] == 0; };
  const auto classify = [&](const Pair& q) {
    if (q.a == q.b) {
      const std::uint64_t na = size(q.a);
      return leaf(q.a) || na * (na - 1) / 2 <= direct_pairs ? Action::P2P : Action::Split;
    }
    if (size(q.a) * size(q.b) <= direct_pairs) return Action::P2P;
    const double dx = zx_[q.a] - zx_[q.b], dy = zy_[q.a] - zy_[q.b], dz = zz_[q.a] - zz_[q.b];
    // Multipole acceptance: r_A + r_B < θ |z_A − z_B| (θ = 0 accepts nothing).
    if (radius_[q.a] + radius_[q.b] < theta * std::sqrt(dx * dx + dy * dy + dz * dz)) return Action::M2L;
    if (leaf(q.a) && leaf(q.b)) return Action::P2P;
    return Action::Split;
  };
  // The sub-interactions of a split, in order: self(c) and (c, c') for c < c',
  // or the larger-radius non-leaf's children against the other cell.
  const auto children = [&](const Pair& q, std::array<Pair, 36>& out) {
    std::size_t k = 0;
    if (q.a == q.b) {
      const std::uint32_t c0 = t.first_child[q.a], c1 = c0 + t.child_count[q.a];
      for (std::uint32_t c = c0; c < c1; ++c) {
        out[k++] = {c, c};
        for (std::uint32_t d = c + 1; d < c1; ++d) out[k++] = {c, d};
      }
      return k;
    }
    const bool split_a = !leaf(q.a) && (leaf(q.b) || radius_[q.a] >= radius_[q.b]);
    const std::uint32_t s = split_a ? q.a : q.b;
    for (std::uint32_t c = t.first_child[s]; c < t.first_child[s] + t.child_count[s]; ++c)
      out[k++] = split_a ? Pair{c, q.b} : Pair{q.a, c};
    return k;
  };

  // Seeds: expand every splittable task one level at a time, in order.
  std::vector<Pair> tasks{{0, 0}}, next;
  std::array<Pair, 36> sub;
  while (tasks.size() < kWalkTasks) {
    next.clear();
    bool split = false;
    for (const Pair& q : tasks) {
      if (classify(q) != Action::Split) {
        next.push_back(q);
        continue;
      }
      split = true;
      const std::size_t k = children(q, sub);
      next.insert(next.end(), sub.begin(), sub.begin() + std::ptrdiff_t(k));
    }
    tasks.swap(next);
    if (!split) break;
  }
  stats_.tasks = tasks.size();

  task_lists_.resize(std::max(task_lists_.size(), tasks.size()));
  parallel::for_blocks("fmm_walk", tasks.size(), 1, [&](std::size_t b, std::size_t e, std::size_t) {
    std::array<Pair, 36> local;
    for (std::size_t i = b; i < e; ++i) {
      TaskLists& lists = task_lists_[i];
      lists.m2l.clear();
      lists.p2p.clear();
      lists.stack.assign(1, tasks[i]);
      while (!lists.stack.empty()) {
        const Pair q = lists.stack.back();
        lists.stack.pop_back();
        switch (classify(q)) {
          case Action::M2L: lists.m2l.push_back(q); break;
          case Action::P2P: lists.p2p.push_back(q); break;
          case Action::Split: {
            const std::size_t k = children(q, local);
            for (std::size_t c = k; c-- > 0;) lists.stack.push_back(local[c]);  // popped in order
            break;
          }
        }
      }
    }
  });
  // Concatenate in task order.
  std::vector<std::size_t> m2l_at(tasks.size() + 1, 0), p2p_at(tasks.size() + 1, 0);
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    m2l_at[i + 1] = m2l_at[i] + task_lists_[i].m2l.size();
    p2p_at[i + 1] = p2p_at[i] + task_lists_[i].p2p.size();
  }
  m2l_.resize(m2l_at.back());
  p2p_.resize(p2p_at.back());
  parallel::for_blocks("fmm_walk_lists", tasks.size(), 4, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t i = b; i < e; ++i) {
      std::copy(task_lists_[i].m2l.begin(), task_lists_[i].m2l.end(), m2l_.begin() + std::ptrdiff_t(m2l_at[i]));
      std::copy(task_lists_[i].p2p.begin(), task_lists_[i].p2p.end(), p2p_.begin() + std::ptrdiff_t(p2p_at[i]));
    }
  });
  stats_.m2l = m2l_.size();
  stats_.p2p_cells = p2p_.size();
  std::uint64_t pairs = 0;
  for (const Pair& q : p2p_) pairs += q.a == q.b ? size(q.a) * (size(q.a) - 1) / 2 : size(q.a) * size(q.b);
  stats_.p2p_pairs = pairs;
  // With an active set, only the interactions with an active cell on a side
  // are computed (fmm.hpp): a stable filter keeps their order. The walk
  // itself and the figures above stay the full evaluation's (the same for
  // any active set, and on MPI ranks the one-rank figures).
  if (!active_cell_.empty()) {
    const auto inactive = [&](const Pair& q) { return !cell_active(q.a) && !cell_active(q.b); };
    std::erase_if(m2l_, inactive);
    std::erase_if(p2p_, inactive);
  }
  stats_.m2l_computed = m2l_.size();
  stats_.p2p_cells_computed = p2p_.size();
}

// The mutual M2L in chunks: D(z_A − z_B) once per pair, both sides' local
// contributions into the buffer (in parallel), then added to the cells by
// fixed node ranges, each cell's in list order.
template <class Real>
template <int P>
void Fmm<Real>::interact_m2l() {
  using O = Order<P>;
  const double eps2 = settings_.softening * settings_.softening;
  const std::size_t total = m2l_.size(), nodes = zx_.size();
  buffer_.resize(std::max(buffer_.size(), kM2lChunk * 2 * O::KL));
  for (std::size_t start = 0; start < total; start += kM2lChunk) {
    const std::size_t count = std::min(kM2lChunk, total - start);
    parallel::for_blocks("fmm_m2l", count, 64, [&](std::size_t b, std::size_t e, std::size_t) {
      std::array<std::uint32_t, kLanes> ia, ib;
      for (std::size_t q0 = b; q0 < e; q0 += kLanes) {
        // Lane l: pair q0 + l; lanes past the block's end repeat its last pair (their results are dropped).
        for (std::size_t l = 0; l < kLanes; ++l) {
          const Pair pr = m2l_[start + std::min(q0 + l, e - 1)];
          ia[l] = pr.a;
          ib[l] = pr.b;
        }
        m2l_lanes<P>(ia, ib, zx_.data(), zy_.data(), zz_.data(), multipoles_.data(), eps2,
                     &buffer_[q0 * 2 * O::KL], std::min(kLanes, e - q0));
      }
    });
    const std::size_t ranges = std::min(owner_ranges(), nodes);
    parallel::for_blocks("fmm_m2l_add", ranges, 1, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t r = b; r < e; ++r) {
        const std::size_t lo = nodes * r / ranges, hi = nodes * (r + 1) / ranges;
        for (std::size_t q = 0; q < count; ++q) {
          const Pair pr = m2l_[start + q];
          const double* ca = &buffer_[q * 2 * O::KL];
          if (pr.a >= lo && pr.a < hi && cell_active(pr.a)) {
            double* C = &locals_[std::size_t(pr.a) * O::KL];
            for (std::size_t k = 0; k < O::KL; ++k) C[k] += ca[k];
          }
          if (pr.b >= lo && pr.b < hi && cell_active(pr.b)) {
            double* C = &locals_[std::size_t(pr.b) * O::KL];
            for (std::size_t k = 0; k < O::KL; ++k) C[k] += ca[O::KL + k];
          }
        }
      }
    });
  }
}

// The mutual P2P in chunks: each interaction's sums for both cells' particles
// into the buffer (in parallel), then added to the particles by fixed slot
// ranges, each particle's in list order. Buffer per cell side: ax, ay, az, φ
// of its particles (structure of arrays). A cell's self-interaction sums each
// particle's terms from all the others (every pair twice, see below).
template <class Real>
void Fmm<Real>::interact_p2p() {
  const double eps2 = settings_.softening * settings_.softening;
  const LinearNodes<Real>& t = tree_.nodes();
  const Real *x = tree_.x().data(), *y = tree_.y().data(), *z = tree_.z().data(), *m = tree_.m().data();
  const std::size_t total = p2p_.size(), n = ax_.size();
  const auto need = [&](const Pair& q) {
    const std::size_t na = t.end[q.a] - t.begin[q.a];
    return 4 * (q.a == q.b ? na : na + (t.end[q.b] - t.begin[q.b]));
  };
  std::size_t start = 0;
  while (start < total) {
    offsets_.clear();
    std::size_t stop = start, used = 0;
    while (stop < total && (stop == start || used + need(p2p_[stop]) <= kP2pBudget)) {
      offsets_.push_back(used);
      used += need(p2p_[stop]);
      ++stop;
    }
    if (buffer_.size() < used) buffer_.resize(used);
    parallel::for_blocks("fmm_p2p", stop - start, 16, [&](std::size_t b, std::size_t e, std::size_t) {
      // The source cell's particles in double, padded with massless ones at
      // the origin to a multiple of kLanes, so that the vector loops below run
      // whole vectors (a padded source adds exactly 0: m = 0, and 1/R = 0 at R = 0).
      std::vector<double> src_x, src_y, src_z, src_m, src_ax, src_ay, src_az, src_phi;
      const auto load = [&](std::uint32_t c) {
        const std::size_t c0 = t.begin[c], nc = t.end[c] - c0, padded = (nc + kLanes - 1) / kLanes * kLanes;
        for (auto* v : {&src_x, &src_y, &src_z, &src_m, &src_ax, &src_ay, &src_az, &src_phi}) v->assign(padded, 0.0);
        for (std::size_t k = 0; k < nc; ++k) {
          src_x[k] = double(x[c0 + k]);
          src_y[k] = double(y[c0 + k]);
          src_z[k] = double(z[c0 + k]);
          src_m[k] = double(m[c0 + k]);
        }
        return padded;
      };
      for (std::size_t q = b; q < e; ++q) {
        const Pair pr = p2p_[start + q];
        const std::uint32_t a0 = t.begin[pr.a], a1 = t.end[pr.a];
        const std::size_t na = a1 - a0;
        double* sa = &buffer_[offsets_[q]];
        double *ax = sa, *ay = ax + na, *az = ay + na, *ap = az + na;
        const std::size_t nb = load(pr.b);
        const double *bx = src_x.data(), *by = src_y.data(), *bz = src_z.data(), *bm = src_m.data();
        double *gx = src_ax.data(), *gy = src_ay.data(), *gz = src_az.data(), *gp = src_phi.data();
        if (pr.a == pr.b) {
          // Within the cell, each particle from all the others: every pair
          // twice, its term on j the negation of its term on i with the same
          // R (x_i − x_j = −(x_j − x_i) exactly), so Σ m a over the cell is
          // zero to round-off as with one mutual term; the loop runs whole vectors.
          for (std::size_t i = 0; i < na; ++i) {
            const double xi = bx[i], yi = by[i], zi = bz[i];
            double vx[kLanes] = {}, vy[kLanes] = {}, vz[kLanes] = {}, vp[kLanes] = {};
            for (std::size_t j0 = 0; j0 < nb; j0 += kLanes) {
#pragma omp simd
              for (std::size_t l = 0; l < kLanes; ++l) {
                const std::size_t j = j0 + l;
                const double dx = bx[j] - xi, dy = by[j] - yi, dz = bz[j] - zi;
                const double inv = inverse_distance(dx * dx + dy * dy + dz * dz + eps2);
                const double mj = j == i ? 0.0 : bm[j];  // not itself
                const double f = mj * inv * inv * inv;
                vx[l] += f * dx;
                vy[l] += f * dy;
                vz[l] += f * dz;
                vp[l] += mj * inv;
              }
            }
            ax[i] = lane_sum(vx);
            ay[i] = lane_sum(vy);
            az[i] = lane_sum(vz);
            ap[i] = -lane_sum(vp);
          }
          continue;
        }
        // Mutual: a_i += m_j d/R³ and a_j −= m_i d/R³ from one term (d = x_j − x_i).
        // With an active set, a side whose cell holds no active particle is
        // not summed (its sums would be dropped): the other side's
        // expressions and order are the mutual loop's, so its bits are too.
        const auto sides = [&]<bool kSideA, bool kSideB>() {
          for (std::uint32_t i = a0; i < a1; ++i) {
            const double xi = double(x[i]), yi = double(y[i]), zi = double(z[i]), mi = double(m[i]);
            double vx[kLanes] = {}, vy[kLanes] = {}, vz[kLanes] = {}, vp[kLanes] = {};
            for (std::size_t j0 = 0; j0 < nb; j0 += kLanes) {
#pragma omp simd
              for (std::size_t l = 0; l < kLanes; ++l) {
                const std::size_t j = j0 + l;
                const double dx = bx[j] - xi, dy = by[j] - yi, dz = bz[j] - zi;
                const double inv = inverse_distance(dx * dx + dy * dy + dz * dz + eps2);
                const double inv3 = inv * inv * inv, fi = bm[j] * inv3, fj = mi * inv3;
                if constexpr (kSideA) {
                  vx[l] += fi * dx;
                  vy[l] += fi * dy;
                  vz[l] += fi * dz;
                  vp[l] += bm[j] * inv;
                }
                if constexpr (kSideB) {
                  gx[j] -= fj * dx;
                  gy[j] -= fj * dy;
                  gz[j] -= fj * dz;
                  gp[j] -= mi * inv;
                }
              }
            }
            if constexpr (kSideA) {
              const std::size_t k = i - a0;
              ax[k] = lane_sum(vx);
              ay[k] = lane_sum(vy);
              az[k] = lane_sum(vz);
              ap[k] = -lane_sum(vp);
            }
          }
        };
        const bool side_a = cell_active(pr.a), side_b = cell_active(pr.b);
        if (side_a && side_b)
          sides.template operator()<true, true>();
        else if (side_a)
          sides.template operator()<true, false>();
        else
          sides.template operator()<false, true>();
        if (!side_b) continue;
        const std::size_t nbr = t.end[pr.b] - t.begin[pr.b];
        double* sb = ap + na;
        std::copy(gx, gx + nbr, sb);
        std::copy(gy, gy + nbr, sb + nbr);
        std::copy(gz, gz + nbr, sb + 2 * nbr);
        std::copy(gp, gp + nbr, sb + 3 * nbr);
      }
    });
    const std::size_t ranges = std::min(owner_ranges(), n);
    parallel::for_blocks("fmm_p2p_add", ranges, 1, [&](std::size_t b, std::size_t e, std::size_t) {
      for (std::size_t r = b; r < e; ++r) {
        const std::size_t lo = n * r / ranges, hi = n * (r + 1) / ranges;
        // Adds one side's sums (cell c, its buffer at `from`) for the slots in [lo, hi).
        const auto add = [&](std::uint32_t c, const double* from) {
          const std::size_t c0 = t.begin[c], c1 = t.end[c], nc = c1 - c0;
          const std::size_t s0 = std::max(c0, lo), s1 = std::min(c1, hi);
          for (std::size_t s = s0; s < s1; ++s) {
            ax_[s] += from[s - c0];
            ay_[s] += from[nc + s - c0];
            az_[s] += from[2 * nc + s - c0];
            phi_[s] += from[3 * nc + s - c0];
          }
        };
        for (std::size_t q = 0; q < stop - start; ++q) {
          const Pair pr = p2p_[start + q];
          const double* from = &buffer_[offsets_[q]];
          if (cell_active(pr.a)) add(pr.a, from);
          if (pr.a != pr.b && cell_active(pr.b)) add(pr.b, from + 4 * std::size_t(t.end[pr.a] - t.begin[pr.a]));
        }
      }
    });
    start = stop;
  }
}

// L2L top down (each child written by its parent's block), then L2P at the
// leaves, then the field out in the particles' order.
template <class Real>
template <int P>
void Fmm<Real>::downward(GravityField<Real>& out, std::size_t block_size) {
  using O = Order<P>;
  const LinearNodes<Real>& t = tree_.nodes();
  const std::size_t count = t.size();
  const int depth = tree_.depth();
  for (int level = 0; level < depth; ++level) {
    const std::size_t lb = level_start_[std::size_t(level)], le = level_start_[std::size_t(level) + 1];
    node_blocks("fmm_l2l", le - lb, [&](std::size_t b, std::size_t e, std::size_t) {
      double T[O::KL], shifted[O::KL];
      for (std::size_t node = lb + b; node < lb + e; ++node) {
        const double* C = &locals_[node * O::KL];
        for (std::uint32_t c = t.first_child[node]; c < t.first_child[node] + t.child_count[node]; ++c) {
          // C_j(child) += Σ_k C_k(parent) T_{k−j}(z_c − z): the same polynomial about z_c.
          powers<O::Q>(zx_[c] - zx_[node], zy_[c] - zy_[node], zz_[c] - zz_[node], T);
          std::fill(shifted, shifted + O::KL, 0.0);
          for (const Term& term : O::l2l) shifted[term.out] += C[term.in] * T[term.other];
          double* Cc = &locals_[std::size_t(c) * O::KL];
          for (std::size_t k = 0; k < O::KL; ++k) Cc[k] += shifted[k];
        }
      }
    });
  }
  const auto x = tree_.x(), y = tree_.y(), z = tree_.z();
  node_blocks("fmm_l2p", count, [&](std::size_t b, std::size_t e, std::size_t) {
    double T[O::KL];
    for (std::size_t node = b; node < e; ++node) {
      if (t.child_count[node] != 0 || !cell_active(std::uint32_t(node))) continue;
      const double* C = &locals_[node * O::KL];
      for (std::uint32_t s = t.begin[node]; s < t.end[node]; ++s) {
        powers<O::Q>(double(x[s]) - zx_[node], double(y[s]) - zy_[node], double(z[s]) - zz_[node], T);
        // Ψ = Σ_k C_k T_k;  a = ∇Ψ: a_a = Σ_{|k| ≤ p} C_{k+e_a} T_k;  φ = −Ψ.
        double psi = 0, gx = 0, gy = 0, gz = 0;
        for (std::size_t k = 0; k < O::KL; ++k) psi += C[k] * T[k];
        for (std::size_t k = 0; k < O::KM; ++k) {
          gx += C[O::gradient[k][0]] * T[k];
          gy += C[O::gradient[k][1]] * T[k];
          gz += C[O::gradient[k][2]] * T[k];
        }
        ax_[s] += gx;
        ay_[s] += gy;
        az_[s] += gz;
        phi_[s] -= psi;
      }
    }
  });
  const auto order = tree_.order();
  parallel::for_blocks("fmm_out", order.size(), block_size, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t s = b; s < e; ++s) {
      const std::uint32_t i = order[s];
      out.acceleration.x[i] = Real(ax_[s]);
      out.acceleration.y[i] = Real(ay_[s]);
      out.acceleration.z[i] = Real(az_[s]);
      out.potential[i] = Real(phi_[s]);
    }
  });
}

template class Fmm<float>;
template class Fmm<double>;

}  // namespace swirl::gravity
