#pragma once
// How both backends turn the samples of one listener call into messages: each sample on its own, so a malformed one
// (a conversion that throws, e.g. an enum value the protocol does not define) is dropped and counted, and never
// costs the other samples of the batch. The log stays bounded under a flood: one line at the 1st, 10th, 100th, ...
// malformed sample of a reader, each with the count so far.

#include <cstdint>
#include <exception>
#include <string>
#include <utility>
#include <vector>

namespace marsala::bus::detail {

/// Malformed samples of one reader [count], and when they are worth a log line.
class MalformedSamples {
 public:
  /// Counts one; true when this one should be logged (the 1st, 10th, 100th, ...).
  bool count() {
    ++count_;
    if (count_ < next_log_) return false;
    next_log_ = next_log_ > UINT64_MAX / 10 ? UINT64_MAX : next_log_ * 10;
    return true;
  }
  std::uint64_t total() const { return count_; }

 private:
  std::uint64_t count_ = 0;
  std::uint64_t next_log_ = 1;
};

/// Appends convert() to `out`; when it throws, counts the sample in `malformed`, calls log(what, total) when the
/// count says so, and returns false. Nothing else escapes but std::bad_alloc from `out` itself.
template <typename T, typename Convert, typename Log>
bool convert_sample(Convert&& convert, std::vector<T>& out, MalformedSamples& malformed, Log&& log) {
  try {
    out.push_back(std::forward<Convert>(convert)());
    return true;
  } catch (const std::exception& e) {
    if (malformed.count()) log(std::string(e.what()), malformed.total());
  } catch (...) {
    if (malformed.count()) log(std::string("unknown error"), malformed.total());
  }
  return false;
}

}  // namespace marsala::bus::detail
