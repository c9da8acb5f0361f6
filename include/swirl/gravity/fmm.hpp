// Fmm<Real>: the fast multipole method with Cartesian expansions and a dual
// tree walk with mutual interactions, after Dehnen's falcON (Dehnen 2000, ApJ
// 536, L39; 2002, J. Comput. Phys. 179, 27; the notation of Dehnen 2014,
// Comput. Astrophys. Cosmol. 1, 1), on swirl's linear octree.
//
// Green's function g(r) = 1/sqrt(r² + ε²) (the Plummer-softened pair law of
// pair_law.hpp), Ψ(x) = Σ_j m_j g(x − x_j), φ = −Ψ, a = ∇Ψ (G = 1).
//
// Expansions, of order p ∈ [2, 5] (all in double; multi-indices n = (n_x, n_y,
// n_z), |n| = n_x + n_y + n_z, n! = n_x! n_y! n_z!, s^n = s_x^{n_x} s_y^{n_y} s_z^{n_z}):
//   multipoles  M_n(B) = Σ_{j∈B} m_j s_j^n / n!,  s_j = x_j − z_B,  |n| ≤ p,
//               about the cell's centre of mass z_B (so the dipole vanishes);
//   derivatives D_m(R) = ∂^m g(R), |m| ≤ p + 1, from the recurrence (Lindsay &
//               Krasny 2001, eq. 8, written for ∂/∂R and unnormalised)
//                 |m| ρ² D_m = −(2|m|−1) Σ_a m_a R_a D_{m−e_a} − (|m|−1) Σ_a m_a(m_a−1) D_{m−2e_a},
//               ρ² = |R|² + ε², D_0 = 1/ρ (it holds for the softened g because
//               ρ² ∂_a g = −R_a g, with ρ² in place of r²);
//   local       C_k(A) = Σ_n (−1)^{|n|} M_n(B) D_{k+n}(z_A − z_B) over |n| ≤ p,
//               |k| + |n| ≤ p + 1, so Ψ(z_A + t) ≈ Σ_{|k| ≤ p+1} C_k t^k / k!
//               and a(z_A + t) = Σ_{|k| ≤ p} C_{k+e_a} t^k / k!: the force keeps
//               every term with |k| + |n| ≤ p (the multipoles to order p, as the
//               Barnes–Hut quadrupole at p = 2), and is exactly the gradient of
//               the potential kept.
// M2M and L2L shift by the binomial theorem (exact for polynomials: the L2L
// moves the local polynomial without changing it); L2P evaluates it at the
// particle. The far field is softened like the near field (g above), so the
// method converges to the softened direct sum as p grows or θ falls.
//
// Multipole acceptance (the one accuracy parameter, θ = GravitySettings::opening):
// two cells A, B interact through their expansions iff
//     r_A + r_B < θ · |z_A − z_B|,
// r_X the cell's radius about z_X (a bound on max |x_j − z_X|: exact for a leaf,
// min(max_c |z_c − z_X| + r_c, the farthest cube corner) above). The expansion of
// (x − x_j) about z_A − z_B then converges with ratio < θ and the relative error
// of one interaction's force falls as θ^{p+1} (Dehnen 2002, section 2.3). θ = 0
// accepts nothing: every interaction is a particle pair, the direct sum's terms.
//
// Dual tree walk (Dehnen 2002, section 3.2): from the root's self-interaction,
//   self(A):    A a leaf, or N_A (N_A − 1)/2 ≤ the M2L's cost in pairs: P2P within A;
//               else self(c) for every child c and interact(c, c') for every c < c';
//   interact(A, B): N_A N_B ≤ the M2L's cost in pairs: P2P (exact and cheaper);
//               else accepted: M2L; else both leaves: P2P;
//               else interact(children of the larger-radius non-leaf, other).
// Every interaction is mutual: one M2L computes D(z_A − z_B) once and fills
// both C(A) (with M(B)) and C(B) (with M(A), D(z_B − z_A) = (−1)^{|m|} D(z_A − z_B));
// one P2P pair term between two cells is added to both particles with opposite
// signs (within a cell each particle sums over all the others, every pair
// twice, the two terms exact negations: x_i − x_j = −(x_j − x_i) in IEEE
// arithmetic, so R and 1/R³ are the same bits; this lets the loop run whole
// SIMD vectors). So the
// total force Σ m_i a_i is zero in exact arithmetic: for the far field
//   F_A = Σ_{|k|+|n| ≤ p} M_k(A) (−1)^{|n|} M_n(B) D_{k+n+e}(R) = −F_B
// (swap k and n; L2L and L2P only move and evaluate the same polynomial), and
// in floating point to round-off.
//
// Determinism: the walk is cut into a fixed set of tasks (the first levels of
// the walk expanded serially to at least 256 tasks), each producing its M2L and
// P2P lists, concatenated in task order: the same lists for any thread count.
// The lists are processed in chunks: every interaction is computed in parallel
// into a buffer (both sides), then the buffers are added to their owners (cells,
// particles) by fixed owner ranges, each owner receiving its terms in list
// order. Upward and downward passes are level by level, each node written by
// one block. So the result is bit-identical for any thread count.
//
// Active sets (block time steps; on MPI ranks, a rank's own particles): a
// cell is active when it holds an active particle. The walk runs in full (its
// figures in FmmStats are the full evaluation's); then only the interactions
// with an active cell on at least one side are kept, in their order, for the
// M2L and the P2P; only active cells receive their terms (a P2P sums only its
// active sides, by the mutual loop's expressions in its order), and only
// active leaves are evaluated (L2P). Every active cell so receives the same
// terms in the same order as in a full evaluation, and every active
// particle's field is the full evaluation's, bit for bit.
// The upward pass covers every particle (the sources are all of them); what
// an evaluation leaves for inactive particles is unspecified.
//
// Units: G = 1; lengths as the positions.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "swirl/core/active_set.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/gravity/field.hpp"
#include "swirl/gravity/linear_octree.hpp"

namespace swirl::gravity {

struct FmmSettings {
  int order = 3;             // p ∈ [2, 5]: multipoles to order p, force terms to total order p
  double opening = 0.5;      // θ ∈ [0, 1]: cells interact iff r_A + r_B < θ |z_A − z_B|
  double softening = 0.01;   // ε ≥ 0, near and far field alike
  std::size_t bucket_size = 16;  // a node with more particles is split
};

// Throws std::invalid_argument naming the parameter and its range.
void validate(const FmmSettings& settings);

// What the last evaluation did.
struct FmmStats {
  std::uint64_t m2l = 0;          // cell–cell expansion interactions (each mutual: counts once)
  std::uint64_t p2p_cells = 0;    // P2P cell pairs and cell self-interactions
  std::uint64_t p2p_pairs = 0;    // particle pairs interacting directly (each counts once)
  std::size_t tasks = 0;          // walk tasks
  std::size_t active = 0;         // particles computed (all, or the active set's)
  std::uint64_t m2l_computed = 0, p2p_cells_computed = 0;  // the interactions kept for them
  std::size_t nodes = 0, leaves = 0;
  int depth = 0;
  double tree_seconds = 0;        // keys, sort, nodes (LinearOctree)
  double upward_seconds = 0;      // centres, radii, multipoles (P2M, M2M)
  double walk_seconds = 0;        // the dual tree walk
  double m2l_seconds = 0;
  double p2p_seconds = 0;
  double downward_seconds = 0;    // L2L, L2P and the output
  std::size_t bytes = 0;          // expansions, lists, buffers and the tree
};

template <class Real>
class Fmm {
 public:
  // Validates the settings (std::invalid_argument).
  explicit Fmm(const FmmSettings& settings = {});

  // Overwrites out (resized to p.size()) with the field of p: every particle,
  // or the active ones (by index in p; the others' entries are unspecified).
  // block_size: the per-particle passes' block (results do not depend on it).
  void compute(const ParticleSet<Real>& p, GravityField<Real>& out, std::size_t block_size,
               const ActiveSet& active = {});
  // The same on particles already sorted by 63-bit Morton keys (the
  // simulation's order, as LinearOctree::build_sorted): no sort, no copy.
  void compute_sorted(const ParticleSet<Real>& p, std::span<const std::uint64_t> sorted_keys,
                      const std::array<double, 3>& corner, double side, GravityField<Real>& out,
                      std::size_t block_size, const ActiveSet& active = {});

  const FmmSettings& settings() const { return settings_; }
  const FmmStats& stats() const { return stats_; }
  const LinearOctree<Real>& tree() const { return tree_; }

 private:
  struct Pair {
    std::uint32_t a, b;  // cells; a == b: a P2P self-interaction
  };
  struct TaskLists {
    std::vector<Pair> m2l, p2p;
    std::vector<Pair> stack;
  };
  void evaluate_order(GravityField<Real>& out, std::size_t block_size, double tree_seconds, const ActiveSet& active);
  void mark_active_cells(const ActiveSet& active);
  template <int P>
  void evaluate(GravityField<Real>& out, std::size_t block_size);
  template <int P>
  void upward();
  void walk(std::uint64_t direct_pairs);
  template <int P>
  void interact_m2l();
  void interact_p2p();
  template <int P>
  void downward(GravityField<Real>& out, std::size_t block_size);
  LinearTreeSettings tree_settings() const;

  FmmSettings settings_;
  FmmStats stats_;
  LinearOctree<Real> tree_;
  // Per node (the tree's node order): centre of mass, mass, radius; multipoles
  // (stride coef_count(p)) and local coefficients (stride coef_count(p + 1)).
  std::vector<double> zx_, zy_, zz_, mass_, radius_;
  std::vector<double> multipoles_, locals_;
  std::vector<std::size_t> level_start_;  // nodes of level l: [level_start_[l], level_start_[l + 1])
  // Per node: holds an active particle (empty: every node is active); and the
  // count of active sorted slots before each slot, which finds them.
  std::vector<std::uint8_t> active_cell_;
  std::vector<std::uint64_t> active_before_;
  // Whether cell c's terms are wanted: no active set, or c holds an active particle.
  bool cell_active(std::uint32_t c) const { return active_cell_.empty() || active_cell_[c] != 0; }
  // Per sorted slot: the field, summed in double.
  std::vector<double> ax_, ay_, az_, phi_;
  std::vector<Pair> m2l_, p2p_;
  std::vector<TaskLists> task_lists_;
  std::vector<double> buffer_;
  std::vector<std::size_t> offsets_;
};

extern template class Fmm<float>;
extern template class Fmm<double>;

}  // namespace swirl::gravity
