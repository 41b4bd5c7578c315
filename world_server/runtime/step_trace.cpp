#include "marsala/world_server/runtime/step_trace.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "marsala/core/error.hpp"

namespace marsala::world_server {
namespace {

double us_between(StepTimes::Clock::time_point from, StepTimes::Clock::time_point to) {
  return std::chrono::duration<double, std::micro>(to - from).count();
}

}  // namespace

std::string trace_event_json(const TraceSpan& span) {
  // Names are the fixed words of step_spans(): nothing to escape.
  const std::string cpu = span.cpu_us >= 0.0 ? fmt::format(R"(,"cpu_us":{:.0f})", span.cpu_us) : std::string();
  return fmt::format(
      R"({{"name":"{}","cat":"{}","ph":"X","ts":{:.3f},"dur":{:.3f},"pid":1,"tid":{},"args":{{"step":{}{}}}}})",
      span.name, span.track == kWorldTrack ? "world" : "agent", span.start_us, span.duration_us, span.track,
      span.step, cpu);
}

std::vector<TraceSpan> step_spans(const StepTimes& t, StepTimes::Clock::time_point origin) {
  std::vector<TraceSpan> spans;
  const auto add = [&](std::uint32_t track, const char* name, StepTimes::Clock::time_point from,
                       StepTimes::Clock::time_point to) {
    spans.push_back({track, name, us_between(origin, from), us_between(from, to), t.step});
  };
  add(kWorldTrack, "step", t.start, t.recorded);
  add(kWorldTrack, "frames", t.start, t.frames_out);
  add(kWorldTrack, "collect", t.frames_out, t.collected);
  add(kWorldTrack, "apply", t.collected, t.applied);
  add(kWorldTrack, "record", t.applied, t.recorded);
  add(kWorldTrack, "status", t.recorded, t.published);
  for (const AgentAnswer& a : t.answers) {
    const StepTimes::Clock::time_point read = std::max(a.read, t.frames_out);
    add(a.agent, "answer", t.frames_out, read);
    if (a.decision_us == 0) continue;
    const double answer_us = spans.back().duration_us;
    const double decide_us = std::min(static_cast<double>(a.decision_us), answer_us);
    spans.push_back({a.agent, "decide", spans.back().start_us + answer_us - decide_us, decide_us, t.step,
                     static_cast<double>(a.decision_cpu_us)});
  }
  for (std::uint32_t id : t.missed) add(id, "missed", t.frames_out, t.collected);
  return spans;
}

StepTrace::StepTrace(std::string path, StepTimes::Clock::time_point origin)
    : path_(std::move(path)), origin_(origin) {
  file_ = std::fopen((path_ + ".tmp").c_str(), "w");
  if (file_ == nullptr)
    throw IoError(fmt::format("--trace {}: cannot write {}.tmp: {}", path_, path_, std::strerror(errno)));
  write(R"({"displayTimeUnit":"ms","traceEvents":[)"
        "\n"
        R"({"name":"process_name","ph":"M","pid":1,"tid":0,"args":{"name":"marsala-world"}})");
  write(",\n" R"({"name":"thread_name","ph":"M","pid":1,"tid":0,"args":{"name":"world"}})");
}

StepTrace::~StepTrace() {
  if (file_ != nullptr) std::fclose(file_);
  if (!finished_) {
    std::error_code ignored;
    std::filesystem::remove(path_ + ".tmp", ignored);
  }
}

void StepTrace::name_tracks(std::uint32_t agents) {
  for (std::uint32_t id = 1; id <= agents; ++id)
    write(fmt::format(",\n"
                      R"({{"name":"thread_name","ph":"M","pid":1,"tid":{},"args":{{"name":"agent {}"}}}})",
                      id, id));
}

void StepTrace::step(const StepTimes& times) {
  std::string text;
  for (const TraceSpan& span : step_spans(times, origin_)) {
    text += ",\n";
    text += trace_event_json(span);
  }
  write(text);
}

void StepTrace::finish() {
  write("\n]}\n");
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!closed) throw IoError(fmt::format("--trace {}: cannot write {}.tmp", path_, path_));
  std::error_code error;
  std::filesystem::rename(path_ + ".tmp", path_, error);
  if (error) throw IoError(fmt::format("--trace {}: cannot rename {}.tmp into place: {}", path_, path_, error.message()));
  finished_ = true;
}

void StepTrace::write(const std::string& text) {
  if (file_ == nullptr || std::fwrite(text.data(), 1, text.size(), file_) != text.size())
    throw IoError(fmt::format("--trace {}: cannot write {}.tmp", path_, path_));
}

}  // namespace marsala::world_server
