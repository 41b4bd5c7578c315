#pragma once
// One way to name an enum's values: each enum lists its (value, name) pairs once in a table, and to_string /
// from_string are read off that table. An unknown name throws InvalidArgument listing the valid ones.
//
//   constexpr EnumName<Heading> kHeadingNames[] = {{Heading::kEast, "east"}, {Heading::kWest, "west"}};
//   std::string to_string(Heading h) { return enum_to_string(kHeadingNames, h); }
//   Heading heading_from_string(const std::string& s) { return enum_from_string(kHeadingNames, s, "heading"); }

#include <cstddef>
#include <string>

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala {

/// One value of an enum and its name.
template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

/// The name of `value` in `names`; "unknown" for a value the table lacks (e.g. a cast from a bad integer).
template <typename Enum, std::size_t N>
std::string enum_to_string(const EnumName<Enum> (&names)[N], Enum value) {
  for (const EnumName<Enum>& n : names)
    if (n.value == value) return n.name;
  return "unknown";
}

/// The value named `name` in `names`; throws InvalidArgument "unknown <kind> 'name'; valid: a, b, c".
template <typename Enum, std::size_t N>
Enum enum_from_string(const EnumName<Enum> (&names)[N], const std::string& name, const char* kind) {
  std::string valid;
  for (const EnumName<Enum>& n : names) {
    if (name == n.name) return n.value;
    valid += (valid.empty() ? "" : ", ") + std::string(n.name);
  }
  throw InvalidArgument(fmt::format("unknown {} '{}'; valid: {}", kind, name, valid));
}

}  // namespace marsala
