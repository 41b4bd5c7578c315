#include "marsala/monitor/follow.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <ostream>
#include <set>
#include <utility>
#include <vector>

#include "marsala/monitor/progress.hpp"
#include "marsala/monitor/world_gate.hpp"
#include "marsala/protocol/end_reason.hpp"

namespace marsala::monitor {
namespace {

using Clock = std::chrono::steady_clock;

/// Reader history of the events topic: a slow terminal must not make tail miss events [samples].
constexpr std::int32_t kEventDepth = 256;

std::string where(const bus::Participant& participant) {
  return fmt::format("domain {} ({})", participant.domain_id(), bus::to_string(participant.vendor()));
}

/// What one tail has printed so far, and the merge of statuses and events into one stream of lines.
class TailPrinter {
 public:
  TailPrinter(const TailOptions& options, std::ostream& out, std::ostream& err)
      : options_(options),
        run_id_(options.run_id),
        out_(out),
        err_(err),
        pacing_(options.every_steps, options.interval) {}

  /// Prints a batch in step order: each status after the events of its step and earlier (the world
  /// publishes a step's events before its status; statuses are taken before events, so the events of a
  /// taken status are in the batch). Events of a step whose status has not come yet wait for it: the take
  /// of events can catch the next step's events before its status. Stops at the final status and keeps
  /// the events after it; returns whether a status of the followed run came.
  bool print(const std::vector<protocol::WorldStatus>& statuses, const std::vector<protocol::WorldEvent>& events) {
    pending_.insert(pending_.end(), events.begin(), events.end());
    bool got_status = false;
    std::size_t next_event = 0;
    for (const protocol::WorldStatus& status : statuses) {
      if (!follows(status)) continue;
      got_status = true;
      if (!status.running) {
        final_ = status;
        break;
      }
      while (next_event < pending_.size() && pending_[next_event].step <= status.step) print_event(pending_[next_event++]);
      if (!status_step_ || status.step > *status_step_) status_step_ = status.step;
      if (pacing_.take(status.step, Clock::now())) print_status(status);
    }
    for (; next_event < pending_.size(); ++next_event) {
      const protocol::WorldEvent& e = pending_[next_event];
      if (final_)
        late_events_.push_back(e);
      else if (status_step_ && e.step <= *status_step_)
        print_event(e);
      else
        break;  // its step's status has not come yet
    }
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(next_event));
    out_.flush();
    return got_status;
  }

  const std::optional<protocol::WorldStatus>& final_status() const { return final_; }
  bool run_over_seen() const {
    if (run_over_printed_) return true;
    for (const protocol::WorldEvent& e : late_events_)
      if (e.kind == protocol::EventKind::kRunOver) return true;
    return false;
  }
  void add_late_events(const std::vector<protocol::WorldEvent>& events) {
    late_events_.insert(late_events_.end(), events.begin(), events.end());
  }

  /// The end of the run: its last events, its last step line, the summary.
  void print_final() {
    for (const protocol::WorldEvent& e : late_events_) print_event(e);
    late_events_.clear();
    print_status(*final_);
    out_ << format_run_summary(*final_) << '\n';
    // A run that did not complete: what each robot waited for (the account of a stall, docs/runtime.md#stall).
    const bool waiting = std::any_of(final_->agents.begin(), final_->agents.end(),
                                     [](const protocol::AgentStatus& a) { return a.alive && !a.waiting_for.empty(); });
    if (!final_->completed && (stalled_ || waiting)) {
      out_ << (stalled_ ? "stalled: " : "") << "what each robot waited for at the end:\n";
      for (const std::string& line : format_waiting(*final_)) out_ << "  " << line << '\n';
    }
    out_.flush();
  }

  void print_stopped() {
    print_pending();
    if (last_)
      out_ << fmt::format("tail stopped after step {} of run {}\n", last_->step, printable(last_->run_id));
    else
      out_ << "tail stopped before any world status\n";
    out_.flush();
  }

  /// The end of a tail whose world is gone: what is pending, then one line saying so.
  void print_world_gone(std::chrono::duration<double> after) {
    print_pending();
    out_ << fmt::format("world gone: no live world status writer for {:g} s{}; tail ends\n", after.count(),
                        last_seen());
    out_.flush();
  }

  /// True once a status of the followed run came.
  bool followed() const { return status_step_.has_value() || final_.has_value(); }

  std::string last_seen() const {
    if (!last_) return "";
    return fmt::format(" (last: step {} of run {})", last_->step, printable(last_->run_id));
  }

 private:
  bool follows(const protocol::WorldStatus& status) {
    if (run_id_.empty()) run_id_ = status.run_id;
    if (status.run_id == run_id_) return true;
    if (ignored_runs_.insert(status.run_id).second)
      err_ << fmt::format("marsala-monitor: ignoring run '{}' (following '{}')\n", printable(status.run_id),
                          printable(run_id_));
    return false;
  }

  void print_status(const protocol::WorldStatus& status) {
    std::vector<std::uint32_t> ids;
    for (const protocol::AgentStatus& a : status.agents) ids.push_back(a.agent_id);
    if (!last_ || ids != header_ids_) {
      out_ << format_step_header(status, options_.format) << '\n';
      header_ids_ = std::move(ids);
    }
    out_ << format_step_line(status, options_.format) << '\n';
    last_ = status;
  }

  /// The events still waiting for their step's status, when no status will come.
  void print_pending() {
    for (const protocol::WorldEvent& e : pending_) print_event(e);
    pending_.clear();
  }

  void print_event(const protocol::WorldEvent& event) {
    if (event.kind == protocol::EventKind::kRunOver) {
      run_over_printed_ = true;
      stalled_ = protocol::find_end_reason(event.detail) == protocol::EndReason::kStalled;
    }
    out_ << format_event(event, options_.format) << '\n';
  }

  const TailOptions& options_;
  std::string run_id_;
  std::ostream& out_;
  std::ostream& err_;
  std::optional<protocol::WorldStatus> last_;
  std::optional<protocol::WorldStatus> final_;
  std::vector<std::uint32_t> header_ids_;
  std::vector<protocol::WorldEvent> late_events_;
  std::vector<protocol::WorldEvent> pending_;  ///< events of steps whose status has not come yet
  std::optional<std::uint64_t> status_step_;    ///< the highest step of a status taken so far
  std::set<std::string> ignored_runs_;
  LinePacing pacing_;  ///< which step lines are printed (--every, --interval); the final one always is
  bool run_over_printed_ = false;
  bool stalled_ = false;  ///< the run_over event named the end reason 'stalled'
};

}  // namespace

int run_tail(bus::Participant& participant, const TailOptions& options, const StopSource& stop, std::ostream& out,
             std::ostream& err) {
  const std::shared_ptr<bus::Signal>& signal = stop.signal();
  auto statuses =
      participant.create_reader<protocol::WorldStatus>({"", signal, bus::Durability::kTransientLocal, kStatusDepth});
  std::unique_ptr<bus::Reader<protocol::WorldEvent>> events;
  if (options.events)
    events = participant.create_reader<protocol::WorldEvent>({"", signal, bus::Durability::kVolatile, kEventDepth});
  const std::string run = options.run_id.empty() ? std::string() : fmt::format(", run {}", printable(options.run_id));
  err << fmt::format("marsala-monitor: tailing {}{}; Ctrl-C stops", where(participant), run) << std::endl;

  TailPrinter printer(options, out, err);
  WorldGate gate(err);  // only the run's own world speaks for it
  std::optional<Clock::time_point> deadline;
  std::optional<Clock::time_point> gone_since;  ///< since when no status writer has been alive
  if (options.timeout) deadline = Clock::now() + to_clock(*options.timeout);
  for (;;) {
    // Statuses before events: every event published before a taken status is then taken too.
    std::vector<protocol::WorldStatus> status_batch = gate.statuses(statuses->take_received());
    // In step order: a transient-local replay may be overtaken by a newer live sample.
    std::stable_sort(status_batch.begin(), status_batch.end(),
                     [](const auto& a, const auto& b) { return a.step < b.step; });
    std::vector<protocol::WorldEvent> event_batch =
        events ? gate.events(events->take_received()) : std::vector<protocol::WorldEvent>{};
    const bool got_status = printer.print(status_batch, event_batch);
    if (printer.final_status()) break;
    if (stop.stop_requested()) {  // after the take: what arrived before the stop is printed
      printer.print_stopped();
      return 0;
    }
    if (deadline && got_status) deadline = Clock::now() + to_clock(*options.timeout);
    // The world is gone once its status writer has not been alive for gone_after (docs/runtime.md#discovery-star):
    // a world that died, was killed or stays paused or cut off, which would otherwise leave tail waiting for ever.
    const Clock::time_point now = Clock::now();
    if (got_status || statuses->alive_writers() > 0 || !printer.followed() || options.gone_after.count() <= 0)
      gone_since.reset();
    else if (!gone_since)
      gone_since = now;
    std::optional<Clock::time_point> wake = deadline;
    if (gone_since) {
      const Clock::time_point gone_at = *gone_since + to_clock(options.gone_after);
      if (now >= gone_at) {
        printer.print_world_gone(options.gone_after);
        err << fmt::format("marsala-monitor: the world is gone: no live world status writer on {} for {:g} s{}",
                           where(participant), options.gone_after.count(), printer.last_seen())
            << std::endl;
        return kExitWorldGone;
      }
      wake = wake ? std::min(*wake, gone_at) : gone_at;
    }
    if (deadline && now >= *deadline) {
      err << fmt::format("marsala-monitor: no world status on {} for {:g} s{}", where(participant),
                         options.timeout->count(), printer.last_seen())
          << std::endl;
      return 1;
    }
    if (wake)
      signal->wait_until(*wake);
    else
      signal->wait_for(std::chrono::hours(1));
  }

  // The run is over: the world may still be sending its last events (kRunOver comes last); wait briefly.
  if (events) {
    const Clock::time_point drain_until = Clock::now() + to_clock(options.drain);
    while (!printer.run_over_seen() && !stop.stop_requested() && Clock::now() < drain_until) {
      signal->wait_until(drain_until);
      printer.add_late_events(gate.events(events->take_received()));
    }
  }
  printer.print_final();
  return 0;
}

int run_status(bus::Participant& participant, const StatusOptions& options, const StopSource& stop, std::ostream& out,
               std::ostream& err) {
  auto statuses =
      participant.create_reader<protocol::WorldStatus>({"", stop.signal(), bus::Durability::kTransientLocal, 1});
  const Clock::time_point deadline = Clock::now() + to_clock(options.timeout);
  WorldGate gate(err);  // only a world that proves itself speaks for its run
  std::optional<protocol::WorldStatus> latest;
  std::optional<Clock::time_point> print_at;
  for (;;) {
    // The newest (the last of the highest step): a transient-local replay may arrive after a live sample.
    for (protocol::WorldStatus& s : gate.statuses(statuses->take_received()))
      if (!latest || s.step >= latest->step) latest = std::move(s);
    if (latest && !print_at) print_at = Clock::now() + to_clock(options.listen);
    if (latest && (Clock::now() >= *print_at || stop.stop_requested())) {
      for (const std::string& line : format_status_table(*latest)) out << line << '\n';
      out.flush();
      return 0;
    }
    if (print_at) {
      stop.signal()->wait_until(*print_at);
      continue;
    }
    if (stop.stop_requested()) {
      err << "marsala-monitor: stopped before a world status arrived" << std::endl;
      return 1;
    }
    if (Clock::now() >= deadline) {
      err << fmt::format("marsala-monitor: no world server on {}: no world status within {:g} s", where(participant),
                         options.timeout.count())
          << std::endl;
      return 1;
    }
    stop.signal()->wait_until(deadline);
  }
}

}  // namespace marsala::monitor
