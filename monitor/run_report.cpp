#include "marsala/monitor/run_report.hpp"

#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <fstream>
#include <sstream>
#include <vector>

#include "idl/run_summary.pb.h"
#include "marsala/core/error.hpp"
#include "marsala/monitor/format.hpp"
#include "marsala/protocol/end_reason.hpp"

namespace marsala::monitor {
namespace {

namespace fs = std::filesystem;

std::string number(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

/// Why a run that did not complete ended, in words (docs/runtime.md#end-reasons).
std::string why_not(const std::string& end_reason) {
  if (const std::optional<protocol::EndReason> reason = protocol::find_end_reason(end_reason)) {
    switch (*reason) {
      case protocol::EndReason::kMaxSteps: return "it reached its step limit (max_steps)";
      case protocol::EndReason::kNoLiveAgents: return "every agent was dropped (no_live_agents)";
      case protocol::EndReason::kSignal: return "it was stopped by a signal (signal)";
      case protocol::EndReason::kCompleted: break;
    }
  }
  return "it ended with '" + printable(end_reason) + "'";
}

std::string join(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& n : names) text += (text.empty() ? "" : ", ") + n;
  return text;
}

}  // namespace

std::string run_report(const std::string& dir) {
  const fs::path path = fs::path(dir) / "summary.json";
  std::ifstream in(path);
  if (!in) throw IoError(path.string() + ": cannot be read (no run ended in " + dir + "?)");
  std::stringstream text;
  text << in.rdbuf();
  proto::RunSummary s;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = true;
  const auto status = google::protobuf::util::JsonStringToMessage(text.str(), &s, options);
  if (!status.ok()) throw ParseError(path.string(), 0, "not a run summary: " + status.ToString());

  std::string out = printable(s.scenario());
  const std::string steps = std::to_string(s.steps()) + (s.steps() == 1 ? " step" : " steps");
  const std::string timing = number("%.1f s", s.wall_seconds()) + " (admission " + number("%.1f s", s.admit_seconds()) + ")";
  if (s.completed())
    out += " completed after " + steps + " in " + timing + "\n";
  else
    out += " did not complete: " + why_not(s.end_reason()) + ", after " + steps + " in " + timing + "\n";
  out += "  agents " + std::to_string(s.agents()) + " (" + std::to_string(s.admitted()) + " admitted, " +
         std::to_string(s.dropped()) + " dropped), " + number("%.3f", s.deposited_volume_m3()) + " m3 deposited";
  if (s.completion() == "payload_path")
    out += s.path_found() ? ", payload path " + number("%.1f m", s.path_length_m()) : ", no payload path yet";
  if (s.completion() == "level_site") out += ", site " + number("%.1f %%", 100.0 * s.site_level_fraction()) + " level";
  out += "\n";
  if (s.missed_deadlines() > 0 || s.rejected_requests() > 0)
    out += "  " + std::to_string(s.missed_deadlines()) + " missed deadlines, " + std::to_string(s.rejected_requests()) +
           " rejected requests (events.log says which)\n";
  out += "  progress " + number("%.1f %%", 100.0 * s.progress());
  if (!s.progress_detail().empty()) out += ": " + printable(s.progress_detail());
  out += "\n";

  std::vector<std::string> pictures, others;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".png") pictures.push_back(name);
    else if (name == "summary.json" || name == "events.log" || name == "run.log" || name == "logs")
      others.push_back(e.is_directory() ? name + "/" : name);
  }
  // final.png first, then the rest by name: the picture people look at first leads.
  std::sort(pictures.begin(), pictures.end(), [](const std::string& a, const std::string& b) {
    return (a == "final.png") != (b == "final.png") ? a == "final.png" : a < b;
  });
  std::sort(others.begin(), others.end());
  if (!pictures.empty()) out += "  pictures in " + dir + ": " + join(pictures) + "\n";
  // The time-lapse of --frames-every, when the run drew one.
  const fs::path frames_dir = fs::path(dir) / "frames";
  std::size_t frames = 0;
  bool video = false;
  for (const fs::directory_entry& e : fs::directory_iterator(frames_dir, ec)) {
    const std::string name = e.path().filename().string();
    frames += name.rfind("frame_", 0) == 0 && e.path().extension() == ".png" ? 1 : 0;
    video = video || name == "timelapse.mp4";
  }
  if (frames > 0)
    out += "  time-lapse in " + frames_dir.string() + ": " + std::to_string(frames) + " frame" +
           (frames == 1 ? "" : "s") + (video ? ", timelapse.mp4" : "") + "\n";
  out += "  everything else in " + dir + ": " + join(others) + "\n";
  return out;
}

}  // namespace marsala::monitor
