#include "marsala/monitor/run_report.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
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

/// Why a run that did not complete ended, in words (docs/runtime.md#end-reasons).
std::string why_not(const std::string& end_reason) {
  if (const std::optional<protocol::EndReason> reason = protocol::find_end_reason(end_reason)) {
    switch (*reason) {
      case protocol::EndReason::kMaxSteps: return "it reached its step limit (max_steps)";
      case protocol::EndReason::kNoLiveAgents: return "every agent was dropped (no_live_agents)";
      case protocol::EndReason::kSignal: return "it was stopped by a signal (signal)";
      case protocol::EndReason::kStalled: return "it stopped making progress (stalled)";
      case protocol::EndReason::kCompleted: break;
    }
  }
  return fmt::format("it ended with '{}'", printable(end_reason));
}

/// The stall account of a summary: the quiet stretch, then one line per robot.
std::string stall_account(const proto::StallAccount& stall) {
  std::string out = fmt::format(
      "  stalled: no rise of the progress and no terrain change for {} steps, since step {}; what each robot waited "
      "for:\n",
      stall.stall_steps(), stall.quiet_since_step());
  for (const proto::StalledAgent& a : stall.agents())
    out += fmt::format("    agent {} {}, {:.3f} m3 on board, at ({:.2f}, {:.2f}, {:.2f}) m: {}\n", a.agent_id(),
                       a.state().empty() ? std::string("(no state)") : printable(a.state()), a.material_m3(), a.x_m(),
                       a.y_m(), a.z_m(),
                       a.waiting_for().empty() ? std::string("(nothing said)") : printable(a.waiting_for()));
  return out;
}

/// Where a fork came from (docs/runtime.md#fork): its parent, K, the team from K on and its own --set.
std::string fork_line(const proto::ForkOrigin& fork) {
  std::string left;
  if (!fork.left_agents().empty())
    left = fmt::format(" (agent{} {} left at step {} by choice: not missing)", fork.left_agents_size() == 1 ? "" : "s",
                       fmt::join(fork.left_agents(), ", "), fork.at_step());
  else if (fork.agents() > fork.parent_agents())
    left = fmt::format(" ({} of {} late slot{} joined at step {}{}{})", fork.joined_agents_size(),
                       fork.agents() - fork.parent_agents(), fork.agents() - fork.parent_agents() == 1 ? "" : "s",
                       fork.at_step(),
                       fork.joined_agents().empty() ? "" : fork.joined_agents_size() == 1 ? ": agent " : ": agents ",
                       fmt::join(fork.joined_agents(), ", "));
  const std::string set =
      fork.overrides().empty() ? std::string() : fmt::format(", --set {}", fmt::join(fork.overrides(), " "));
  return fmt::format("  fork of {} at step {}: team {} -> {}{}{}\n", printable(fork.parent()), fork.at_step(),
                     fork.parent_agents(), fork.agents(), left, printable(set));
}

}  // namespace

std::string run_report(const std::string& dir) {
  const fs::path path = fs::path(dir) / "summary.json";
  std::ifstream in(path);
  if (!in) throw IoError(fmt::format("{}: cannot be read (no run ended in {}?)", path.string(), dir));
  std::stringstream text;
  text << in.rdbuf();
  proto::RunSummary s;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = true;
  const auto status = google::protobuf::util::JsonStringToMessage(text.str(), &s, options);
  if (!status.ok()) throw ParseError(path.string(), 0, fmt::format("not a run summary: {}", status.ToString()));

  const std::string outcome =
      s.completed() ? std::string(" completed after") : fmt::format(" did not complete: {}, after", why_not(s.end_reason()));
  std::string out = fmt::format("{}{} {} step{} in {:.1f} s (admission {:.1f} s)\n", printable(s.scenario()), outcome,
                                s.steps(), s.steps() == 1 ? "" : "s", s.wall_seconds(), s.admit_seconds());
  std::string goal;
  if (s.completion() == "payload_path")
    goal = s.path_found() ? fmt::format(", payload path {:.1f} m", s.path_length_m()) : ", no payload path yet";
  if (s.construction_band_width_m() > 0.0)
    goal += fmt::format(", {:.3f} m3 outside the {:.1f} m construction band", s.deposited_outside_band_m3(),
                        s.construction_band_width_m());
  if (s.completion() == "level_site") goal = fmt::format(", site {:.1f} % level", 100.0 * s.site_level_fraction());
  out += fmt::format("  agents {} ({} admitted, {} dropped), {:.3f} m3 deposited{}\n", s.agents(), s.admitted(),
                     s.dropped(), s.deposited_volume_m3(), goal);
  if (s.has_material())
    out += fmt::format("  material {:.3f} of {:.3f} m3 needed: ratio {:.3f} (1 = the exact MARS need), {:.3f} m3 off "
                       "the band\n",
                       s.material().deposited_m3(), s.material().needed_m3(), s.material().ratio(),
                       s.material().off_band_m3());
  if (s.has_fork()) out += fork_line(s.fork());
  if (s.slots_missing() > 0)
    out += fmt::format("  short of {} of {} slots at the end (never admitted, or dropped and not back): agent{} {}\n",
                       s.slots_missing(), s.agents(), s.missing_agents_size() == 1 ? "" : "s",
                       fmt::join(s.missing_agents(), ", "));
  if (s.missed_deadlines() > 0 || s.rejected_requests() > 0)
    out += fmt::format("  {} missed deadlines, {} rejected requests (events.log says which)\n", s.missed_deadlines(),
                       s.rejected_requests());
  const std::string detail =
      s.progress_detail().empty() ? std::string() : fmt::format(": {}", printable(s.progress_detail()));
  out += fmt::format("  progress {:.1f} %{}\n", 100.0 * s.progress(), detail);
  if (s.has_stall()) out += stall_account(s.stall());

  std::vector<std::string> pictures, others;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".png") pictures.push_back(name);
    else if (name == "summary.json" || name == "events.log" || name == "run.log" || name == "logs")
      others.push_back(e.is_directory() ? fmt::format("{}/", name) : name);
  }
  // final.png first, then the rest by name: the picture people look at first leads.
  std::sort(pictures.begin(), pictures.end(), [](const std::string& a, const std::string& b) {
    return (a == "final.png") != (b == "final.png") ? a == "final.png" : a < b;
  });
  std::sort(others.begin(), others.end());
  if (!pictures.empty()) out += fmt::format("  pictures in {}: {}\n", dir, fmt::join(pictures, ", "));
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
    out += fmt::format("  time-lapse in {}: {} frame{}{}\n", frames_dir.string(), frames, frames == 1 ? "" : "s",
                       video ? ", timelapse.mp4" : "");
  out += fmt::format("  everything else in {}: {}\n", dir, fmt::join(others, ", "));
  return out;
}

}  // namespace marsala::monitor
