// The gravity solver's parameters and the names a scene uses for them.
//
// Units: G = 1 N-body units (Hénon units for the initial conditions: G = M = 1,
// E = −1/4). Lengths (ε) are in the same unit as positions.
//
// Invariants (validate() enforces them, with std::invalid_argument naming the
// parameter and its allowed range): 0 ≤ λ ≤ 1, ε ≥ 0 and finite, both sizes ≥ 1.
#pragma once

#include <cstddef>
#include <string_view>

namespace swirl::gravity {

// How the force is computed: the O(N²) reference or the paper's octree.
enum class Method { direct, barnes_hut };

// How the Barnes–Hut work is split (Demiroz et al. 2011, section 4):
//   subdomain  4.1  Morton runs of ≤ subdomain_size particles, one local tree each;
//   subtree    4.2  one global tree cut depth-first into units of ≤ subtree_nodes nodes;
//   global     the modern baseline: one global tree, particle blocks on the threads.
enum class Scheme { subdomain, subtree, global };

std::string_view to_string(Method method);
std::string_view to_string(Scheme scheme);
// Parse "direct" | "barnes_hut" and "subdomain" | "subtree" | "global"; an
// unknown name throws std::invalid_argument listing the allowed ones.
Method parse_method(std::string_view name);
Scheme parse_scheme(std::string_view name);

struct GravitySettings {
  Method method = Method::barnes_hut;
  Scheme scheme = Scheme::global;
  // λ of section 2: a node whose size / distance(particle, centre of mass) < λ
  // is used as one particle, otherwise it is opened. 0 gives the direct sum.
  double opening = 0.5;
  // Plummer softening ε: forces use |r|² + ε² in place of |r|².
  double softening = 0.01;
  // Section 4.1 / 5: particles per local tree at most (the paper's local store limit).
  std::size_t subdomain_size = 208;
  // Section 4.2 / 5: nodes per sub-tree unit at most (the paper's local store limit).
  std::size_t subtree_nodes = 370;
};

// Throws std::invalid_argument if a parameter is outside its range.
void validate(const GravitySettings& settings);

}  // namespace swirl::gravity
