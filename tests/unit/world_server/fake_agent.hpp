#pragma once
// Scripted agents for the runtime tests: each runs on its own thread with its own in-process participant and
// speaks the runtime protocol (hello until admitted, then frames in, requests out on its partition).

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "marsala/bus/bus.hpp"

namespace marsala::world_server::testing {

/// What a fake agent does with its frames.
enum class FakeMode {
  kWalker,   ///< walks straight to its target, at most max_step_m per step
  kSilent,   ///< is admitted, then never answers
  kQuitter,  ///< walks, then vanishes (endpoints destroyed) when the frame of `quit_at_step` arrives
  kStander,  ///< stays where it is: answers every frame with an empty request that stands
};

struct FakeAgentConfig {
  int domain = 0;
  std::uint32_t id = 1;
  std::uint64_t session = 1;
  RobotBody body;
  FakeMode mode = FakeMode::kWalker;
  std::uint64_t quit_at_step = 0;
  bool deposit_first = false;  ///< at step 0, also deposit two cube layers on the cell centred at (0.55, 1.95)
  double timeout_s = 30.0;     ///< gives up after this long
  std::optional<std::uint64_t> ask_at_step;  ///< after answering this step's frame, hello once more (still counted in?)
};

class FakeAgent {
 public:
  explicit FakeAgent(FakeAgentConfig config) : config_(config), thread_([this] { run(); }) {}
  ~FakeAgent() {
    stop_ = true;
    join();
  }
  void join() {
    if (thread_.joinable()) thread_.join();
  }
  /// Frames taken so far, one per step as a real agent takes them (copy; safe while running). A copy of the frame
  /// just taken (the world writes one again to a reader that matched after the first: docs/runtime.md#resends) is
  /// answered again but not listed; copies() counts those.
  std::vector<protocol::SensorFrame> frames() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }
  /// Copies of an already taken frame received so far [count].
  int copies() const { return copies_; }
  bool admitted() const { return admitted_; }
  /// Admissions for this agent received after it asked again (ask_at_step) [count].
  int answers_after_ask() const { return answers_after_ask_; }
  /// The refusal reason, when refused (read after join()).
  const std::string& refusal() const { return refusal_; }

 private:
  void run() {
    using namespace std::chrono_literals;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(config_.timeout_s);
    auto participant = bus::make_participant({bus::Vendor::kInProcess, config_.domain});
    auto signal = std::make_shared<bus::Signal>();
    auto hellos = participant->create_writer<protocol::AgentHello>();
    auto admissions = participant->create_reader<protocol::Admission>({"", signal});
    protocol::AgentHello hello;
    hello.agent_id = config_.id;
    hello.session = config_.session;
    hello.name = "fake-" + std::to_string(config_.id);
    hello.behaviour = "scripted";
    hello.body = config_.body;
    protocol::Admission admission;
    while (!admitted_ && refusal_.empty()) {
      if (stop_ || std::chrono::steady_clock::now() > give_up) return;
      hellos->write(hello);
      signal->wait_for(20ms);
      for (const protocol::Admission& a : admissions->take()) {
        if (a.agent_id != config_.id || a.session != config_.session) continue;
        if (a.accepted) {
          admission = a;
          admitted_ = true;
        } else {
          refusal_ = a.reason;
        }
      }
    }
    if (!admitted_) return;
    const std::string partition = protocol::partition_for(admission.run_id, config_.id, admission.session);
    auto frames = participant->create_reader<protocol::SensorFrame>({partition, signal});
    auto requests = participant->create_writer<protocol::ActionRequest>({partition, nullptr});
    bool asked = false;
    while (!stop_ && std::chrono::steady_clock::now() < give_up) {
      signal->wait_for(20ms);
      for (const protocol::Admission& a : admissions->take())
        if (asked && a.agent_id == config_.id && a.session == config_.session) ++answers_after_ask_;
      for (const protocol::SensorFrame& f : frames->take()) {
        {
          std::lock_guard<std::mutex> lock(mutex_);
          if (!frames_.empty() && frames_.back().step == f.step && frames_.back().run_over == f.run_over)
            ++copies_;
          else
            frames_.push_back(f);
        }
        if (f.run_over) return;
        if (config_.mode == FakeMode::kSilent) continue;
        if (config_.mode == FakeMode::kQuitter && f.step >= config_.quit_at_step) return;  // as if the process died
        requests->write(decide(f, admission));
        if (config_.ask_at_step && !asked && f.step >= *config_.ask_at_step) {
          hellos->write(hello);
          asked = true;
        }
      }
    }
  }

  protocol::ActionRequest decide(const protocol::SensorFrame& f, const protocol::Admission& a) const {
    protocol::ActionRequest r;
    r.agent_id = config_.id;
    r.session = config_.session;
    r.step = f.step;
    r.state = "walking";
    r.waiting_for = "its target\n";  // the world keeps it printable
    if (config_.mode == FakeMode::kStander) {
      r.state = "standing";
      r.standing = true;
      return r;
    }
    const double dx = a.assignment.target.x - f.x_m, dy = a.assignment.target.y - f.y_m;
    const double d = std::sqrt(dx * dx + dy * dy);
    if (d > 0.0) {
      r.move = true;
      const double s = std::min(1.0, config_.body.max_step_m / d);
      r.target_x_m = d <= config_.body.max_step_m ? a.assignment.target.x : f.x_m + s * dx;
      r.target_y_m = d <= config_.body.max_step_m ? a.assignment.target.y : f.y_m + s * dy;
    }
    if (config_.deposit_first && f.step == 0) {
      const double layer =
          std::pow(config_.body.cube_size_m, 3) / (a.assignment.world.cell_size_m * a.assignment.world.cell_size_m);
      const int row = a.assignment.world.rows - 1 -
                      static_cast<int>(std::floor((1.95 - a.assignment.world.yll_m) / a.assignment.world.cell_size_m));
      const int col = static_cast<int>(std::floor((0.55 - a.assignment.world.xll_m) / a.assignment.world.cell_size_m));
      r.depositions.push_back({row, col, 2 * layer});
    }
    return r;
  }

  FakeAgentConfig config_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> admitted_{false};
  std::atomic<int> copies_{0};
  std::atomic<int> answers_after_ask_{0};
  std::string refusal_;
  mutable std::mutex mutex_;
  std::vector<protocol::SensorFrame> frames_;
  std::thread thread_;
};

}  // namespace marsala::world_server::testing
