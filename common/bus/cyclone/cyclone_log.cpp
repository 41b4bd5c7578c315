#include "marsala/bus/cyclone/cyclone_log.hpp"

#include <dds/dds.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <string_view>

#include "marsala/bus/detail/log_repeats.hpp"

namespace marsala::bus::cyclone {
namespace {

std::mutex g_mutex;
detail::RepeatedMessages g_repeats;  // guarded by g_mutex

/// Cyclone's log sink: called on Cyclone's threads; nothing may escape into them.
void sink(void*, const dds_log_data_t* data) {
  try {
    std::string_view line(data->message, data->size);
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    std::string_view text = line;
    text.remove_prefix(std::min(data->hdrsize, text.size()));  // the header holds the time and thread
    std::uint64_t count = 0;
    {
      const std::lock_guard<std::mutex> lock(g_mutex);
      count = g_repeats.count(detail::message_kind(text));
    }
    if (count == 0) return;
    const std::string out = count == 1 ? fmt::format("{}\n", line)
                                       : fmt::format("{} ({} messages of this kind so far)\n", line, count);
    std::fwrite(out.data(), 1, out.size(), stderr);
  } catch (...) {
  }
}

}  // namespace

void bound_cyclone_log() {
  static std::once_flag once;
  std::call_once(once, [] { dds_set_log_sink(&sink, nullptr); });
}

}  // namespace marsala::bus::cyclone
