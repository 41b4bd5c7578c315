#include "marsala/world_server/runtime/request_selection.hpp"

#include <algorithm>

namespace marsala::world_server {

RequestTake RequestSelection::take(std::uint32_t id, bool answers) {
  if (answers && !answered_[id - 1]) {
    answered_[id - 1] = true;
    return RequestTake::kAnswer;
  }
  if (taken_[id - 1] >= kMaxRequestsPerPartition) {
    ++surplus_;
    return RequestTake::kSurplus;
  }
  ++taken_[id - 1];
  return RequestTake::kOther;
}

bool RequestSelection::all_answered(const std::vector<std::uint32_t>& ids) const {
  return std::all_of(ids.begin(), ids.end(), [&](std::uint32_t id) { return answered_[id - 1]; });
}

}  // namespace marsala::world_server
