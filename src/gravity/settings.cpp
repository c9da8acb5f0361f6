#include "swirl/gravity/settings.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace swirl::gravity {

namespace {
constexpr std::array<std::pair<std::string_view, Method>, 2> kMethods{{
    {"direct", Method::direct}, {"barnes_hut", Method::barnes_hut}}};
constexpr std::array<std::pair<std::string_view, Scheme>, 3> kSchemes{{
    {"subdomain", Scheme::subdomain}, {"subtree", Scheme::subtree}, {"global", Scheme::global}}};
constexpr std::array<std::pair<std::string_view, Tree>, 2> kTrees{{{"paper", Tree::paper}, {"linear", Tree::linear}}};
constexpr std::array<std::pair<std::string_view, Multipole>, 2> kMultipoles{{
    {"monopole", Multipole::monopole}, {"quadrupole", Multipole::quadrupole}}};
constexpr std::array<std::pair<std::string_view, Criterion>, 2> kCriteria{{
    {"paper", Criterion::paper}, {"barnes", Criterion::barnes}}};
constexpr std::array<std::pair<std::string_view, Walk>, 2> kWalks{{{"group", Walk::group}, {"particle", Walk::particle}}};

template <class Enum, std::size_t N>
Enum parse(std::string_view what, std::string_view name, const std::array<std::pair<std::string_view, Enum>, N>& table) {
  std::string allowed;
  for (const auto& [n, value] : table) {
    if (n == name) return value;
    allowed += fmt::format("{}\"{}\"", allowed.empty() ? "" : ", ", n);
  }
  throw std::invalid_argument(fmt::format("unknown gravity {} \"{}\" (allowed: {})", what, name, allowed));
}

template <class Enum, std::size_t N>
std::string_view name_of(Enum value, const std::array<std::pair<std::string_view, Enum>, N>& table) {
  for (const auto& [n, v] : table)
    if (v == value) return n;
  return "?";
}
}  // namespace

std::string_view to_string(Method method) { return name_of(method, kMethods); }
std::string_view to_string(Scheme scheme) { return name_of(scheme, kSchemes); }
std::string_view to_string(Tree tree) { return name_of(tree, kTrees); }
std::string_view to_string(Multipole multipole) { return name_of(multipole, kMultipoles); }
std::string_view to_string(Criterion criterion) { return name_of(criterion, kCriteria); }
std::string_view to_string(Walk walk) { return name_of(walk, kWalks); }
Walk parse_walk(std::string_view name) { return parse("walk", name, kWalks); }
Tree parse_tree(std::string_view name) { return parse("tree", name, kTrees); }
Multipole parse_multipole(std::string_view name) { return parse("multipole", name, kMultipoles); }
Criterion parse_criterion(std::string_view name) { return parse("opening criterion", name, kCriteria); }
Method parse_method(std::string_view name) { return parse("method", name, kMethods); }
Scheme parse_scheme(std::string_view name) { return parse("scheme", name, kSchemes); }

void validate(const GravitySettings& s) {
  // Written so that NaN fails every test.
  if (!(s.opening >= 0 && s.opening <= 1))
    throw std::invalid_argument(fmt::format("gravity opening angle lambda = {} is outside [0, 1] "
                                            "(0 gives the direct sum, the paper uses 0.3 to 0.9)", s.opening));
  if (!(s.softening >= 0 && std::isfinite(s.softening)))
    throw std::invalid_argument(fmt::format("gravity softening epsilon = {} must be finite and >= 0", s.softening));
  if (s.subdomain_size < 1) throw std::invalid_argument("gravity subdomain_size must be at least 1 particle");
  if (s.subtree_nodes < 1) throw std::invalid_argument("gravity subtree_nodes must be at least 1 node");
  if (s.bucket_size < 1) throw std::invalid_argument("gravity bucket_size must be at least 1 particle");
  if (s.group_size < 1) throw std::invalid_argument("gravity group_size must be at least 1 particle");
}

}  // namespace swirl::gravity
