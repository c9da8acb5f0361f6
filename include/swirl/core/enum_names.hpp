// EnumName: the one table that spells an enum's values as words, for scene
// files, messages and command-line options. Each enum that users name keeps a
// table `kXxxNames` next to its definition, and every reader and writer of the
// names goes through it, so a name is written exactly once.
//
// Invariants of a table: every value of the enum appears once, every name once;
// the table's order is the order names are listed in messages and docs.
#pragma once

#include <optional>
#include <span>
#include <string_view>

namespace swirl {

template <class Enum>
struct EnumName {
  std::string_view name;
  Enum value;
};

// The name of `value`, or "" when the table lacks it (a value cast from an
// out-of-range integer).
template <class Enum>
constexpr std::string_view enum_name(std::span<const EnumName<Enum>> table, Enum value) {
  for (const auto& entry : table)
    if (entry.value == value) return entry.name;
  return {};
}

// The value called `name`, or nullopt.
template <class Enum>
constexpr std::optional<Enum> enum_value(std::span<const EnumName<Enum>> table, std::string_view name) {
  for (const auto& entry : table)
    if (entry.name == name) return entry.value;
  return std::nullopt;
}

}  // namespace swirl
