#pragma once
// Bounded log under a flood of one kind of message (docs/runtime.md#foreign-types): a DDS library that logs every
// sample it cannot read (Cyclone prints a line per foreign or undecodable sample) is cut down to the 1st, 10th,
// 100th ... message of each kind, as malformed samples are (sample_conversion.hpp). A message's kind is its text with
// the digits taken out (sequence numbers, times, counts), so that one writer's flood is one kind.

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

namespace marsala::bus::detail {

/// The kind of log message `text`: each run of decimal digits replaced by '#'.
inline std::string message_kind(std::string_view text) {
  std::string kind;
  kind.reserve(text.size());
  bool in_digits = false;
  for (const char c : text) {
    const bool digit = std::isdigit(static_cast<unsigned char>(c)) != 0;
    if (!digit || !in_digits) kind += digit ? '#' : c;
    in_digits = digit;
  }
  return kind;
}

/// Counts messages per kind; remembers at most kMaxKinds kinds, the others share one count.
class RepeatedMessages {
 public:
  static constexpr std::size_t kMaxKinds = 256;

  /// Counts one message of `kind`; its count so far when it is to be written (the 1st, 10th, 100th ...), else 0.
  std::uint64_t count(const std::string& kind) {
    auto it = counts_.find(kind);
    if (it == counts_.end()) it = counts_.size() < kMaxKinds ? counts_.emplace(kind, 0).first : counts_.find(kOthers);
    if (it == counts_.end()) it = counts_.emplace(kOthers, 0).first;
    const std::uint64_t n = ++it->second;
    std::uint64_t power = 1;
    while (power < n && power <= UINT64_MAX / 10) power *= 10;
    return power == n ? n : 0;
  }
  /// Kinds remembered (at most kMaxKinds + 1).
  std::size_t kinds() const { return counts_.size(); }

 private:
  static constexpr const char* kOthers = "\x01others";
  std::map<std::string, std::uint64_t> counts_;
};

}  // namespace marsala::bus::detail
