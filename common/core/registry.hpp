#pragma once
// A registry of variants by name (behaviours, goal synthesizers): filled explicitly by register_builtins(), an
// unknown name is an error that lists the valid ones.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala {

/// Factories of `Product` by name; `kind` names the variant family in messages ("behaviour", ...).
template <typename Product, typename... Args>
class Registry {
 public:
  using Factory = std::function<std::unique_ptr<Product>(Args...)>;

  explicit Registry(std::string kind) : kind_(std::move(kind)) {}

  /// Registers a factory; throws InvalidArgument when the name is empty or taken.
  void add(const std::string& name, Factory factory) {
    if (name.empty() || factories_.count(name) != 0)
      throw InvalidArgument(kind_ + " name '" + name + "' is empty or already registered");
    factories_.emplace(name, std::move(factory));
  }
  /// Throws InvalidArgument listing the valid names when `name` is not registered.
  void require(const std::string& name) const {
    if (contains(name)) return;
    std::string valid;
    for (const auto& [n, f] : factories_) valid += (valid.empty() ? "" : ", ") + n;
    throw InvalidArgument("unknown " + kind_ + " '" + name + "'; valid: " + (valid.empty() ? "(none)" : valid));
  }
  /// Makes the named variant; throws InvalidArgument listing the valid names when it is unknown.
  std::unique_ptr<Product> make(const std::string& name, Args... args) const {
    require(name);
    return factories_.at(name)(std::forward<Args>(args)...);
  }
  /// The registered names, sorted.
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& [n, f] : factories_) out.push_back(n);
    return out;
  }
  bool contains(const std::string& name) const { return factories_.count(name) != 0; }

 private:
  std::string kind_;
  std::map<std::string, Factory> factories_;
};

}  // namespace marsala
