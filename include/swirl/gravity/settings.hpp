// The gravity solver's parameters and the names a scene uses for them.
//
// Units: G = 1 N-body units (Hénon units for the initial conditions: G = M = 1,
// E = −1/4). Lengths (ε) are in the same unit as positions.
//
// Invariants (validate() enforces them, with std::invalid_argument naming the
// parameter and its allowed range): 0 ≤ λ (θ) ≤ 1, ε ≥ 0 and finite, every size ≥ 1.
//
// Which tree: the scheme `global` walks `tree` (the linear octree by default,
// or the paper's insertion-built tree); `subdomain` and `subtree` are the
// paper's and always use the paper's tree. multipole, criterion and
// bucket_size apply to the linear tree only: the paper's tree is monopole
// with the λ rule (the scene loader refuses other choices for it).
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

#include "swirl/core/enum_names.hpp"

namespace swirl::gravity {

// How the force is computed: the O(N²) reference, the paper's octree
// (Barnes–Hut), or the fast multipole method (fmm.hpp: cell–cell expansions
// of order fmm_order with a dual tree walk, on the linear octree).
enum class Method { Direct, BarnesHut, Fmm };

// How the Barnes–Hut work is split (Demiroz et al. 2011, section 4):
//   subdomain  4.1  Morton runs of ≤ subdomain_size particles, one local tree each;
//   subtree    4.2  one global tree cut depth-first into units of ≤ subtree_nodes nodes;
//   global     the modern baseline: one global tree, particle blocks on the threads.
enum class Scheme { Subdomain, Subtree, Global };

// Which octree the global scheme walks:
//   paper   the paper's tree, built by inserting particles one by one (Fig. 1);
//   linear  built from sorted 63-bit Morton keys (linear_octree.hpp).
enum class Tree { Paper, Linear };

// The expansion a linear-tree node's field is computed from: monopole (mass at
// the centre of mass) or monopole + traceless quadrupole about the centre of mass.
enum class Multipole { Monopole, Quadrupole };

// When a node is opened, d = |centre of mass − particle|, l = the node's side:
//   paper   the paper's rule, open if l / d ≥ λ;
//   barnes  Barnes' modified rule, open if d < l / θ + δ, δ = |centre of mass −
//           geometric centre| (linear_octree.hpp says which failure each prevents).
enum class Criterion { Paper, Barnes };

// How the linear tree is walked:
//   group     one walk per group of ≤ group_size particles (a leaf or a small
//             subtree), opening from the node's centre of mass to the group's
//             bounding box, then the group's interaction list evaluated for all
//             its particles by the SIMD kernels (interaction_kernels.hpp);
//   particle  one walk per particle: the group walk's slow twin and reference.
enum class Walk { Group, Particle };

// How the subdomain scheme cuts the particles into sub-domains (section 4.1, 5):
//   adaptive  Morton cells from the root, split while a cell holds more than
//             subdomain_size particles, packed greedily in Morton order (ours);
//   paper     the paper's fixed split of the bounding cube into 8³ = 512 cells,
//             packed in Morton order into sub-domains of ≤ subdomain_size
//             particles; a cell holding more is cut into equal runs.
enum class SubdomainSplit { Adaptive, Paper };

// How the subtree scheme cuts the global tree into units (section 4.2.1):
//   units  whole sub-trees packed depth first into units of ≤ subtree_nodes
//          nodes, independent of the thread count (ours);
//   parts  the paper's rule: the node total divided by subtree_parts (its
//          number of SPEs), units of ⌈nodes / parts⌉ nodes at most.
enum class SubtreeSplit { Units, Parts };

// What a subtree unit does with the nodes above it (those straddling units):
//   opened    always opened, never used as a cluster (ours: the simplest way to
//             count every mass once);
//   clusters  the paper's replicated upper levels: every unit walks them and may
//             use one as a cluster, which then counts for the unit holding the
//             node's first descendant only; the others skip it. The sum over
//             units is then the global walk's field.
enum class UpperNodes { Opened, Clusters };

// The names scenes, messages and options use: the only place they are spelt.
inline constexpr std::array<EnumName<Method>, 3> kMethodNames{
    {{"direct", Method::Direct}, {"barnes_hut", Method::BarnesHut}, {"fmm", Method::Fmm}}};
inline constexpr std::array<EnumName<Scheme>, 3> kSchemeNames{
    {{"subdomain", Scheme::Subdomain}, {"subtree", Scheme::Subtree}, {"global", Scheme::Global}}};
inline constexpr std::array<EnumName<Tree>, 2> kTreeNames{{{"paper", Tree::Paper}, {"linear", Tree::Linear}}};
inline constexpr std::array<EnumName<Multipole>, 2> kMultipoleNames{
    {{"monopole", Multipole::Monopole}, {"quadrupole", Multipole::Quadrupole}}};
inline constexpr std::array<EnumName<Criterion>, 2> kCriterionNames{{{"paper", Criterion::Paper}, {"barnes", Criterion::Barnes}}};
inline constexpr std::array<EnumName<Walk>, 2> kWalkNames{{{"group", Walk::Group}, {"particle", Walk::Particle}}};
inline constexpr std::array<EnumName<SubdomainSplit>, 2> kSubdomainSplitNames{
    {{"adaptive", SubdomainSplit::Adaptive}, {"paper", SubdomainSplit::Paper}}};
inline constexpr std::array<EnumName<SubtreeSplit>, 2> kSubtreeSplitNames{
    {{"units", SubtreeSplit::Units}, {"parts", SubtreeSplit::Parts}}};
inline constexpr std::array<EnumName<UpperNodes>, 2> kUpperNodesNames{
    {{"opened", UpperNodes::Opened}, {"clusters", UpperNodes::Clusters}}};

std::string_view to_string(Method method);
std::string_view to_string(Scheme scheme);
std::string_view to_string(Tree tree);
std::string_view to_string(Multipole multipole);
std::string_view to_string(Criterion criterion);
std::string_view to_string(Walk walk);
std::string_view to_string(SubdomainSplit split);
std::string_view to_string(SubtreeSplit split);
std::string_view to_string(UpperNodes upper);
// Parse "direct" | "barnes_hut" | "fmm" and "subdomain" | "subtree" | "global"; an
// unknown name throws std::invalid_argument listing the allowed ones.
Method parse_method(std::string_view name);
Scheme parse_scheme(std::string_view name);
// "paper" | "linear", "monopole" | "quadrupole", "paper" | "barnes"; the same errors.
Tree parse_tree(std::string_view name);
Multipole parse_multipole(std::string_view name);
Criterion parse_criterion(std::string_view name);
// "group" | "particle"; the same errors.
Walk parse_walk(std::string_view name);
// "adaptive" | "paper", "units" | "parts", "opened" | "clusters"; the same errors.
SubdomainSplit parse_subdomain_split(std::string_view name);
SubtreeSplit parse_subtree_split(std::string_view name);
UpperNodes parse_upper_nodes(std::string_view name);

struct GravitySettings {
  Method method = Method::BarnesHut;
  Scheme scheme = Scheme::Global;
  Tree tree = Tree::Linear;  // the global scheme's tree
  Multipole multipole = Multipole::Quadrupole;  // linear tree
  Criterion criterion = Criterion::Barnes;      // linear tree
  // Linear tree: a node with more particles than this is split (measured in
  // docs/performance/gravity-tree.md).
  std::size_t bucket_size = 16;
  // Linear tree: per-group or per-particle walk, and the group walk's group
  // size (particles at most, unless one leaf holds more; docs/performance/gravity-tree.md).
  Walk walk = Walk::Group;
  std::size_t group_size = 256;
  // The linear tree's interaction kernels: explicit SIMD, or their scalar twin
  // (the reference; core/kernel_path.hpp).
  bool simd = true;
  // Linear tree under GravityForce: physically reorder the ParticleSet along
  // the Morton curve at every evaluation (ids survive), so the walk and the
  // integrator stream through memory.
  bool reorder = true;
  // λ of section 2 (θ of Barnes' rule for the linear tree's default criterion): a node whose size / distance(particle, centre of mass) < λ
  // is used as one particle, otherwise it is opened. 0 gives the direct sum.
  // Method::Fmm: θ of the multipole acceptance r_A + r_B < θ |z_A − z_B|
  // (cell radii about the centres of mass, fmm.hpp); 0 gives the direct sum.
  double opening = 0.5;
  // Plummer softening ε: forces use |r|² + ε² in place of |r|².
  double softening = 0.01;
  // Section 4.1 / 5: particles per local tree at most (the paper's local store limit).
  std::size_t subdomain_size = 208;
  // Section 4.2 / 5: nodes per sub-tree unit at most (the paper's local store limit).
  std::size_t subtree_nodes = 370;
  SubdomainSplit subdomain_split = SubdomainSplit::Adaptive;
  SubtreeSplit subtree_split = SubtreeSplit::Units;
  // SubtreeSplit::Parts: the paper's number of SPEs (a scene value, never the
  // thread count, so that results do not depend on the threads).
  std::size_t subtree_parts = 8;
  UpperNodes upper_nodes = UpperNodes::Opened;
  // Method::Fmm: the expansion order p ∈ [2, 5] (multipoles to order p, the
  // force's terms to total order p; its error falls as θ^{p+1}). The linear
  // octree's bucket_size and reorder apply too; scheme, tree, multipole,
  // criterion, walk, group_size and simd are Barnes–Hut's and ignored.
  unsigned fmm_order = 3;
};

// Throws std::invalid_argument if a parameter is outside its range.
void validate(const GravitySettings& settings);

}  // namespace swirl::gravity
