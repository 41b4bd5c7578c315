#include "marsala/monitor/progress.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <vector>

#include "marsala/monitor/format.hpp"
#include "marsala/monitor/world_gate.hpp"

namespace marsala::monitor {
namespace {

using Clock = std::chrono::steady_clock;

/// Samples closer than this in the world's wall time add nothing to the rates [s].
constexpr double kSampleSpacingS = 0.1;

}  // namespace

LinePacing::LinePacing(std::uint64_t every_steps, std::chrono::duration<double> interval)
    : every_steps_(every_steps), interval_(to_clock(interval)) {}

bool LinePacing::take(std::uint64_t step, Clock::time_point now) {
  if (last_step_) {
    if (every_steps_ > 1 && step / every_steps_ <= *last_step_ / every_steps_) return false;
    if (interval_ > Clock::duration::zero() && now - last_time_ < interval_) return false;
  }
  last_step_ = step;
  last_time_ = now;
  return true;
}

ProgressMeter::ProgressMeter(double window_s) : window_s_(window_s > 0.0 ? window_s : 30.0) {}

void ProgressMeter::add(double wall_seconds, std::uint64_t step, double progress) {
  if (!std::isfinite(wall_seconds) || !std::isfinite(progress)) return;
  if (!samples_.empty()) {
    const Sample& newest = samples_.back();
    if (step < newest.step) return;  // an older status arriving late
    if (wall_seconds < newest.wall_s) samples_.clear();  // the world's clock restarted (a resumed run)
  }
  const Sample sample{wall_seconds, step, progress};
  // The newest status always counts; the one before it stays only when it is a sample apart from the one before.
  if (samples_.size() >= 2 && samples_.back().wall_s - samples_[samples_.size() - 2].wall_s < kSampleSpacingS)
    samples_.back() = sample;
  else
    samples_.push_back(sample);
  while (samples_.size() > 2 && samples_[1].wall_s <= wall_seconds - window_s_) samples_.pop_front();
}

double ProgressMeter::steps_per_s() const {
  if (samples_.size() < 2) return 0.0;
  const double dt = samples_.back().wall_s - samples_.front().wall_s;
  if (!(dt > 0.0)) return 0.0;
  return static_cast<double>(samples_.back().step - samples_.front().step) / dt;
}

std::optional<double> ProgressMeter::eta_s() const {
  if (samples_.size() < 2) return std::nullopt;
  const double dt = samples_.back().wall_s - samples_.front().wall_s;
  const double dp = samples_.back().progress - samples_.front().progress;
  if (!(dt > 0.0) || !(dp > 0.0)) return std::nullopt;
  return std::max(0.0, 1.0 - samples_.back().progress) * dt / dp;
}

std::string format_duration(std::optional<double> seconds) {
  if (!seconds || !std::isfinite(*seconds) || *seconds < 0.0) return "-";
  const auto s = static_cast<long long>(std::llround(*seconds));
  if (*seconds < 1.0) return "< 1 s";  // "0 s" would say it is over
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

std::string format_progress_line(const protocol::WorldStatus& status, const ProgressMeter& meter, int width) {
  if (status.admitting) return fit_width(fmt::format("admitting agents: {} admitted", status.agents.size()), width);
  const double percent = 100.0 * status.progress;
  const std::string detail =
      status.progress_detail.empty() ? std::string() : fmt::format(" | {}", printable(status.progress_detail));
  // The detail last: on a narrow terminal it is what gets cut.
  if (status.running)
    return fit_width(fmt::format("step {} | {:.1f} % | {:.0f} steps/s | ETA {}{}", status.step, percent,
                                 meter.steps_per_s(), format_duration(meter.eta_s()), detail),
                     width);
  return fit_width(fmt::format("{} at step {} in {:.1f} s | {:.1f} %{}", status.completed ? "completed" : "stopped",
                               status.step, status.wall_seconds, percent, detail),
                   width);
}

int run_progress(bus::Participant& participant, const ProgressOptions& options, const StopSource& stop,
                 std::ostream& out, std::ostream& err) {
  const std::shared_ptr<bus::Signal>& signal = stop.signal();
  auto statuses =
      participant.create_reader<protocol::WorldStatus>({"", signal, bus::Durability::kTransientLocal, kStatusDepth});
  ProgressMeter meter;
  std::string run_id = options.run_id;
  std::optional<protocol::WorldStatus> latest;
  bool latest_printed = true;
  bool line_open = false;  // in place: a line on the screen without its newline yet
  const Clock::duration interval = to_clock(options.interval);
  Clock::time_point last_print = Clock::now() - interval;
  const auto print = [&](const protocol::WorldStatus& s, bool last) {
    const std::string line = format_progress_line(s, meter, options.width);
    if (options.in_place) {
      out << '\r' << line << "\x1b[K";
      line_open = !last;
      if (last) out << '\n';
    } else {
      out << line << '\n';
    }
    out.flush();
    last_print = Clock::now();
  };
  std::optional<Clock::time_point> deadline;
  if (options.timeout) deadline = Clock::now() + to_clock(*options.timeout);
  WorldGate gate(err);  // only the run's own world speaks for it
  for (;;) {
    std::vector<protocol::WorldStatus> batch = gate.statuses(statuses->take_received());
    std::stable_sort(batch.begin(), batch.end(), [](const auto& a, const auto& b) { return a.step < b.step; });
    for (const protocol::WorldStatus& s : batch) {
      if (run_id.empty()) run_id = s.run_id;
      if (s.run_id != run_id) continue;
      if (deadline) deadline = Clock::now() + to_clock(*options.timeout);
      if (!s.admitting) meter.add(s.wall_seconds, s.step, s.progress);
      if (!s.running) {
        print(s, true);
        return 0;
      }
      if (!latest || s.step >= latest->step) {
        latest = s;
        latest_printed = false;
      }
    }
    if (stop.stop_requested()) {
      if (line_open) out << '\n';
      out.flush();
      return 0;
    }
    const Clock::time_point now = Clock::now();
    if (latest && !latest_printed && now - last_print >= interval) {
      print(*latest, false);
      latest_printed = true;
    }
    if (deadline && now >= *deadline) {
      if (line_open) out << '\n';
      err << fmt::format("marsala-monitor: no world status on domain {} for {:g} s", participant.domain_id(),
                         options.timeout->count())
          << std::endl;
      return 1;
    }
    Clock::time_point wake = deadline ? *deadline : now + std::chrono::hours(1);
    if (latest && !latest_printed) wake = std::min(wake, last_print + interval);
    signal->wait_until(wake);
  }
}

}  // namespace marsala::monitor
