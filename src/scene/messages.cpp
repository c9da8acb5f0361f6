#include "messages.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <fmt/format.h>

namespace swirl::scene::detail {

void raise(std::string_view message) {
  std::string out;
  for (const char c : message) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      out += fmt::format("\\x{:02x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
    else
      out += c;
  }
  throw SceneError(out);
}

void fail(std::string_view file, std::string_view where, std::string_view reason) {
  raise(fmt::format("{}: {}: {}", file, where, reason));
}

std::string format_version_problem(std::int64_t version) {
  if (version > static_cast<std::int64_t>(kSceneFormatVersion))
    return fmt::format("the scene is of format {}, newer than this swirl reads (formats 1 to {}): use a newer swirl",
                       version, kSceneFormatVersion);
  if (version < 1) return fmt::format("must be >= 1 (the first scene format), got {}", version);
  return {};
}

std::string vec_text(const Vec3d& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); }
std::string box_text(const Box<double>& b) { return fmt::format("[{}, {}]", vec_text(b.lo), vec_text(b.hi)); }

namespace {

void check_number(double v, const Range& range, std::string_view file, std::string_view where) {
  if (!std::isfinite(v)) fail(file, where, fmt::format("must be finite, got {}", v));
  if (!range.contains(v)) fail(file, where, fmt::format("must be {}, got {}", range.text(), v));
}

void check_vector(const Vec3d& v, std::string_view file, std::string_view where) {
  for (int axis = 0; axis < 3; ++axis)
    if (!std::isfinite(v[axis])) fail(file, fmt::format("{}[{}]", where, axis), fmt::format("must be finite, got {}", v[axis]));
}

template <class Owner>
void check_name(const KeySpec<Owner>& spec, std::string_view name, std::string_view file, std::string_view where) {
  if (std::find(spec.names.begin(), spec.names.end(), name) != spec.names.end()) return;
  std::string allowed;
  for (const auto n : spec.names) allowed += fmt::format("{}'{}'", allowed.empty() ? "" : ", ", n);
  // A typed Scene holds an enum; one without a name was cast from a bad integer.
  if (name.empty()) fail(file, where, fmt::format("is not a valid {} (allowed: {})", spec.noun, allowed));
  fail(file, where, fmt::format("unknown {} '{}' (allowed: {})", spec.noun, name, allowed));
}

}  // namespace

template <class Owner>
void check_value(const KeySpec<Owner>& spec, const KeyValue& value, std::string_view file, std::string_view where) {
  std::visit(
      [&]<class T>(const T& v) {
        if constexpr (std::is_same_v<T, double>) {
          check_number(v, spec.range, file, where);
        } else if constexpr (std::is_same_v<T, std::uint64_t>) {
          if (!spec.range.contains(static_cast<double>(v)))
            fail(file, where, fmt::format("must be {}, got {}", spec.range.text(), v));
        } else if constexpr (std::is_same_v<T, std::string_view>) {
          if (spec.type == KeyType::Name) check_name(spec, v, file, where);
          // A path is handed to C APIs, which would stop at a NUL and open another file.
          if (spec.type == KeyType::Text && v.empty()) fail(file, where, "must not be empty");
          if (spec.type == KeyType::Text && v.find('\0') != std::string_view::npos)
            fail(file, where, "must not hold a NUL character");
        } else if constexpr (std::is_same_v<T, Vec3d>) {
          check_vector(v, file, where);
        } else if constexpr (std::is_same_v<T, std::vector<std::string_view>>) {
          if (v.empty()) fail(file, where, fmt::format("must name at least one {}", spec.noun));
          for (std::size_t i = 0; i < v.size(); ++i) {
            const std::string item = fmt::format("{}[{}]", where, i);
            check_name(spec, v[i], file, item);
            if (std::find(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v[i]) != v.begin() + static_cast<std::ptrdiff_t>(i))
              fail(file, item, fmt::format("'{}' is listed twice", v[i]));
          }
        } else if constexpr (std::is_same_v<T, std::vector<Vec3d>>) {
          for (std::size_t i = 0; i < v.size(); ++i) check_vector(v[i], file, fmt::format("{}[{}]", where, i));
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          for (std::size_t i = 0; i < v.size(); ++i) check_number(v[i], spec.range, file, fmt::format("{}[{}]", where, i));
        }
        // bool: any value is valid.
      },
      value);
}

template void check_value<Scene>(const KeySpec<Scene>&, const KeyValue&, std::string_view, std::string_view);
template void check_value<Probe>(const KeySpec<Probe>&, const KeyValue&, std::string_view, std::string_view);
template void check_value<Inlet>(const KeySpec<Inlet>&, const KeyValue&, std::string_view, std::string_view);
template void check_value<Outlet>(const KeySpec<Outlet>&, const KeyValue&, std::string_view, std::string_view);
template void check_value<ParticleSource>(const KeySpec<ParticleSource>&, const KeyValue&, std::string_view,
                                          std::string_view);

}  // namespace swirl::scene::detail
