#include "swirl/gravity/settings.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace swirl::gravity {

namespace {
template <class Enum, std::size_t N>
Enum parse(std::string_view what, std::string_view name, const std::array<EnumName<Enum>, N>& table) {
  if (const auto value = enum_value<Enum>(table, name)) return *value;
  std::string allowed;
  for (const auto& entry : table) allowed += fmt::format("{}\"{}\"", allowed.empty() ? "" : ", ", entry.name);
  throw std::invalid_argument(fmt::format("unknown gravity {} \"{}\" (allowed: {})", what, name, allowed));
}

template <class Enum, std::size_t N>
std::string_view name_of(Enum value, const std::array<EnumName<Enum>, N>& table) {
  const std::string_view name = enum_name<Enum>(table, value);
  return name.empty() ? "?" : name;
}
}  // namespace

std::string_view to_string(Method method) { return name_of(method, kMethodNames); }
std::string_view to_string(Scheme scheme) { return name_of(scheme, kSchemeNames); }
std::string_view to_string(Tree tree) { return name_of(tree, kTreeNames); }
std::string_view to_string(Multipole multipole) { return name_of(multipole, kMultipoleNames); }
std::string_view to_string(Criterion criterion) { return name_of(criterion, kCriterionNames); }
std::string_view to_string(Walk walk) { return name_of(walk, kWalkNames); }
std::string_view to_string(SubdomainSplit split) { return name_of(split, kSubdomainSplitNames); }
std::string_view to_string(SubtreeSplit split) { return name_of(split, kSubtreeSplitNames); }
std::string_view to_string(UpperNodes upper) { return name_of(upper, kUpperNodesNames); }
Walk parse_walk(std::string_view name) { return parse("walk", name, kWalkNames); }
SubdomainSplit parse_subdomain_split(std::string_view name) { return parse("subdomain split", name, kSubdomainSplitNames); }
SubtreeSplit parse_subtree_split(std::string_view name) { return parse("subtree split", name, kSubtreeSplitNames); }
UpperNodes parse_upper_nodes(std::string_view name) { return parse("upper-node rule", name, kUpperNodesNames); }
Tree parse_tree(std::string_view name) { return parse("tree", name, kTreeNames); }
Multipole parse_multipole(std::string_view name) { return parse("multipole", name, kMultipoleNames); }
Criterion parse_criterion(std::string_view name) { return parse("opening criterion", name, kCriterionNames); }
Method parse_method(std::string_view name) { return parse("method", name, kMethodNames); }
Scheme parse_scheme(std::string_view name) { return parse("scheme", name, kSchemeNames); }

void validate(const GravitySettings& s) {
  // Written so that NaN fails every test.
  if (!(s.opening >= 0 && s.opening <= 1))
    throw std::invalid_argument(fmt::format("gravity opening angle lambda = {} is outside [0, 1] "
                                            "(0 gives the direct sum, the paper uses 0.3 to 0.9)", s.opening));
  if (!(s.softening >= 0 && std::isfinite(s.softening)))
    throw std::invalid_argument(fmt::format("gravity softening epsilon = {} must be finite and >= 0", s.softening));
  if (s.subdomain_size < 1) throw std::invalid_argument("gravity subdomain_size must be at least 1 particle");
  if (s.subtree_nodes < 1) throw std::invalid_argument("gravity subtree_nodes must be at least 1 node");
  if (s.subtree_parts < 1) throw std::invalid_argument("gravity subtree_parts must be at least 1 part");
  if (s.bucket_size < 1) throw std::invalid_argument("gravity bucket_size must be at least 1 particle");
  if (s.group_size < 1) throw std::invalid_argument("gravity group_size must be at least 1 particle");
  if (!(s.fmm_order >= 2 && s.fmm_order <= 5))
    throw std::invalid_argument(fmt::format("gravity fmm_order p = {} is outside [2, 5]", s.fmm_order));
}

}  // namespace swirl::gravity
