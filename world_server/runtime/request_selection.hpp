#pragma once
// Which requests of a step the world takes (docs/runtime.md#load-limits), pure: from each agent's partition its own
// answer for the step always, anything else up to kMaxRequestsPerPartition; the rest is surplus, counted and never
// applied, so a flood on a partition never displaces its agent's request.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace marsala::world_server {

/// Requests taken from one partition in one step besides its agent's answer.
inline constexpr std::size_t kMaxRequestsPerPartition = 8;

/// What becomes of one request read in a step.
enum class RequestTake {
  kAnswer,   ///< the agent's answer for this step (its identity, this step, the first such): always taken
  kOther,    ///< taken and judged by the rules (duplicates, past or future steps, forged identities)
  kSurplus,  ///< beyond the partition's limit: counted, never applied
};

/// The selection of one step over agents 1..agents.
class RequestSelection {
 public:
  explicit RequestSelection(std::size_t agents) : answered_(agents, false), taken_(agents, 0) {}

  /// Decides on a request read from agent `id`'s partition; `answers` = it carries the agent's identity and is for
  /// this step.
  RequestTake take(std::uint32_t id, bool answers);
  /// True when agent `id` has answered this step.
  bool answered(std::uint32_t id) const { return answered_[id - 1]; }
  /// True when every agent of `ids` has answered.
  bool all_answered(const std::vector<std::uint32_t>& ids) const;
  /// Requests counted as surplus so far.
  std::uint32_t surplus() const { return surplus_; }

 private:
  std::vector<bool> answered_;      ///< [id - 1]
  std::vector<std::size_t> taken_;  ///< [id - 1]: requests other than the answer taken
  std::uint32_t surplus_ = 0;
};

}  // namespace marsala::world_server
