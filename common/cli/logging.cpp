#include "marsala/cli/logging.hpp"

#include <fmt/format.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <atomic>
#include <ctime>
#include <mutex>
#include <streambuf>
#include <utility>

#include "marsala/cli/command_line.hpp"
#include "marsala/core/error.hpp"

namespace marsala::cli {
namespace {

std::atomic<std::uint32_t> g_agent_id{0};
std::atomic<LogFormat> g_format{LogFormat::kText};

/// Short level names, the same in both formats.
const char* level_name(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::trace: return "trace";
    case spdlog::level::debug: return "debug";
    case spdlog::level::info: return "info";
    case spdlog::level::warn: return "warn";
    case spdlog::level::err: return "error";
    case spdlog::level::critical: return "critical";
    default: return "off";
  }
}

spdlog::level::level_enum level_from(const std::string& name) {
  if (name == "trace") return spdlog::level::trace;
  if (name == "debug") return spdlog::level::debug;
  if (name == "info") return spdlog::level::info;
  if (name == "warn") return spdlog::level::warn;
  if (name == "error") return spdlog::level::err;
  if (name == "off") return spdlog::level::off;
  throw InvalidArgument(fmt::format("log level '{}' is none of trace, debug, info, warn, error, off", name));
}

std::string utc_time(std::chrono::system_clock::time_point time) {
  const auto since = time.time_since_epoch();
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(since);
  const auto millis = std::chrono::duration_cast<std::chrono::milliseconds>(since - seconds).count();
  const std::time_t t = static_cast<std::time_t>(seconds.count());
  std::tm tm{};
  gmtime_r(&t, &tm);
  return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:02d}.{:03d}Z", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                     tm.tm_hour, tm.tm_min, tm.tm_sec, millis);
}

/// spdlog's formatter for both formats: the process and the agent id it carries are this program's.
class RecordFormatter final : public spdlog::formatter {
 public:
  RecordFormatter(LogFormat format, std::string process) : format_(format), process_(std::move(process)) {}

  void format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) override {
    std::string line = format_log_line(format_, process_, g_agent_id.load(), static_cast<long>(::getpid()), msg.time,
                                       level_name(msg.level), std::string(msg.payload.data(), msg.payload.size()));
    line += '\n';
    dest.append(line.data(), line.data() + line.size());
  }
  std::unique_ptr<spdlog::formatter> clone() const override {
    return std::make_unique<RecordFormatter>(format_, process_);
  }

 private:
  LogFormat format_;
  std::string process_;
};

}  // namespace

void add_log_options(CLI::App& app, LogOptions& options) {
  app.add_option("--log-format", options.format, "log lines on stderr: text, or json (one JSON object per line)")
      ->check(CLI::IsMember({"text", "json"}))
      ->envname("MARSALA_LOG_FORMAT")
      ->capture_default_str();
  app.add_option("--log-level", options.level, "trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
}

void setup_logging(const std::string& process, std::uint32_t agent_id, const LogOptions& options, std::ostream* out) {
  LogFormat format;
  if (options.format == "text")
    format = LogFormat::kText;
  else if (options.format == "json")
    format = LogFormat::kJson;
  else
    throw InvalidArgument(fmt::format("log format '{}' is neither text nor json", options.format));
  const spdlog::level::level_enum level = level_from(options.level);
  spdlog::sink_ptr sink;
  if (out)
    sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(*out, true);
  else
    sink = std::make_shared<spdlog::sinks::stderr_sink_mt>();
  auto logger = std::make_shared<spdlog::logger>(process, std::move(sink));
  logger->set_formatter(std::make_unique<RecordFormatter>(format, process));
  logger->set_level(level);
  logger->flush_on(spdlog::level::trace);  // a line is out when the call returns: crashes lose nothing logged
  g_agent_id = agent_id;
  g_format = format;
  spdlog::set_default_logger(std::move(logger));
}

LoggingScope::LoggingScope(const std::string& process, std::uint32_t agent_id, const LogOptions& options,
                           std::ostream* out)
    : previous_logger_(spdlog::default_logger()), previous_agent_id_(g_agent_id.load()), previous_format_(g_format.load()) {
  setup_logging(process, agent_id, options, out);
}

LoggingScope::~LoggingScope() {
  spdlog::set_default_logger(std::static_pointer_cast<spdlog::logger>(previous_logger_));
  g_agent_id = previous_agent_id_;
  g_format = previous_format_;
}

void set_log_agent_id(std::uint32_t id) { g_agent_id = id; }

LogFormat log_format() { return g_format.load(); }

std::string format_log_line(LogFormat format, const std::string& process, std::uint32_t agent_id, long pid,
                            std::chrono::system_clock::time_point time, const std::string& level,
                            const std::string& message) {
  if (format == LogFormat::kJson) {
    const nlohmann::ordered_json record = {{"time", utc_time(time)},
                                           {"level", level},
                                           {"process", process},
                                           {"agent_id", agent_id == 0 ? nlohmann::ordered_json() : nlohmann::ordered_json(agent_id)},
                                           {"pid", pid},
                                           {"msg", message}};
    return record.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  }
  const std::string who = agent_id == 0 ? process : fmt::format("{}-{}", process, agent_id);
  return fmt::format("{} {:<5} {}[{}]: {}", utc_time(time), level, who, pid, message);
}

void write_exit_error(std::ostream& err, const std::string& text) {
  if (log_format() == LogFormat::kJson && spdlog::default_logger()) {
    spdlog::error("{}", text);
    spdlog::default_logger()->flush();
    return;
  }
  err << text << "\n";
  err.flush();
}

/// Collects characters until a newline, then logs the line.
class LogLineStream::Buffer : public std::streambuf {
 public:
  Buffer(std::string prefix, std::function<std::string(const std::string&)> level_of)
      : prefix_(std::move(prefix)), level_of_(std::move(level_of)) {}
  ~Buffer() override {
    if (!line_.empty()) emit();
  }

 protected:
  int_type overflow(int_type ch) override {
    if (traits_type::eq_int_type(ch, traits_type::eof())) return traits_type::not_eof(ch);
    if (traits_type::to_char_type(ch) == '\n')
      emit();
    else
      line_ += traits_type::to_char_type(ch);
    return ch;
  }

 private:
  void emit() {
    std::string line = std::move(line_);
    line_.clear();
    if (!prefix_.empty() && line.rfind(prefix_, 0) == 0) line.erase(0, prefix_.size());
    const std::string level = level_of_ ? level_of_(line) : "info";
    spdlog::log(level == "error" ? spdlog::level::err : level == "warn" ? spdlog::level::warn : spdlog::level::info,
                "{}", line);
  }

  std::string prefix_;
  std::function<std::string(const std::string&)> level_of_;
  std::string line_;
};

LogLineStream::LogLineStream(std::string prefix, std::function<std::string(const std::string&)> level_of)
    : std::ostream(nullptr), buffer_(std::make_unique<Buffer>(std::move(prefix), std::move(level_of))) {
  rdbuf(buffer_.get());
}

LogLineStream::~LogLineStream() {
  rdbuf(nullptr);
}

}  // namespace marsala::cli
