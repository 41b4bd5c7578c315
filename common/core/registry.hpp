#pragma once
// The one registry of variants by name (terrain generators, behaviours, goal synthesizers, ...): filled explicitly
// by each family's register_builtins(); an unknown name is an error that lists the valid ones.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala {

/// Entries of type `Entry` by name; `kind` names the family in messages ("behaviour", "terrain generator", ...).
template <typename Entry>
class NamedRegistry {
 public:
  explicit NamedRegistry(std::string kind) : kind_(std::move(kind)) {}

  /// Registers an entry; throws InvalidArgument when the name is empty or taken.
  void add(const std::string& name, Entry entry) {
    if (name.empty() || entries_.count(name) != 0)
      throw InvalidArgument(fmt::format("{} name '{}' is empty or already registered", kind_, name));
    entries_.emplace(name, std::move(entry));
  }
  /// Throws InvalidArgument "unknown <kind> 'name'; valid: a, b" when `name` is not registered.
  void require(const std::string& name) const {
    if (contains(name)) return;
    std::string valid;
    for (const auto& [n, e] : entries_) valid += (valid.empty() ? "" : ", ") + n;
    throw InvalidArgument(fmt::format("unknown {} '{}'; valid: {}", kind_, name, valid.empty() ? "(none)" : valid));
  }
  /// The entry named `name`; throws as require() when it is unknown.
  const Entry& find(const std::string& name) const {
    require(name);
    return entries_.at(name);
  }
  /// The registered names, sorted.
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& [n, e] : entries_) out.push_back(n);
    return out;
  }
  bool contains(const std::string& name) const { return entries_.count(name) != 0; }

 private:
  std::string kind_;
  std::map<std::string, Entry> entries_;
};

/// Factories of `Product` by name, made from `Args`.
template <typename Product, typename... Args>
class Registry : public NamedRegistry<std::function<std::unique_ptr<Product>(Args...)>> {
 public:
  using Factory = std::function<std::unique_ptr<Product>(Args...)>;
  using NamedRegistry<Factory>::NamedRegistry;

  /// Makes the named variant; throws InvalidArgument listing the valid names when it is unknown.
  std::unique_ptr<Product> make(const std::string& name, Args... args) const {
    return this->find(name)(std::forward<Args>(args)...);
  }
};

}  // namespace marsala
