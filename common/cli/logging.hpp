#pragma once
// One log format for every MARSala process that logs (marsala-world, marsala-agent, marsala-monitor): one line per
// record on stderr, carrying the time (UTC), the level, the process and its pid, and for an agent its id.
//
//   text (default):
//     2026-11-24T06:26:08.123Z info  world[4242]: run 'ramp-d80': scenario 'ramp', 300 x 300 cells of 0.1 m, ...
//     2026-11-24T06:26:08.456Z warn  agent-3[4250]: agent 3: ignoring a stale frame for step 12
//   json (--log-format json, or MARSALA_LOG_FORMAT=json): one JSON object per line, the same fields, e.g.
//     {"time":"2026-11-24T06:26:08.123Z","level":"info","process":"world","agent_id":null,"pid":4242,"msg":"..."}
//
// The line a program ends with on an error ("marsala-world: error: ...") goes through write_exit_error(): as it is in
// text (scripts and people read it as the program's answer), as a record at level error in json, so that stderr then
// holds nothing but JSON objects. Usage errors (exit 2) are found before logging starts and stay plain text.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <ostream>
#include <string>

namespace CLI {
class App;
}

namespace marsala::cli {

/// The two log formats.
enum class LogFormat { kText, kJson };

/// What add_log_options() reads from the command line.
struct LogOptions {
  std::string format = "text";  ///< text or json
  std::string level = "info";   ///< trace, debug, info, warn, error, off
};

/// Adds --log-format (text|json; also MARSALA_LOG_FORMAT) and --log-level to `app`.
void add_log_options(CLI::App& app, LogOptions& options);

/// Makes spdlog's default logger write records of `process` ("world", "agent", "monitor"; agent_id 0 = not an
/// agent, or not yet known) to stderr, or to `out` when given (which must outlive the logging), in the chosen format
/// and from the chosen level on. Throws InvalidArgument for an unknown format or level.
void setup_logging(const std::string& process, std::uint32_t agent_id, const LogOptions& options,
                   std::ostream* out = nullptr);

/// setup_logging() for the life of this object; then the logger, format and agent id in use before come back (a
/// program run in-process, e.g. by a test, leaves the process's logging as it found it).
class LoggingScope {
 public:
  LoggingScope(const std::string& process, std::uint32_t agent_id, const LogOptions& options,
               std::ostream* out = nullptr);
  ~LoggingScope();
  LoggingScope(const LoggingScope&) = delete;
  LoggingScope& operator=(const LoggingScope&) = delete;

 private:
  std::shared_ptr<void> previous_logger_;
  std::uint32_t previous_agent_id_;
  LogFormat previous_format_;
};

/// The agent id shown from now on (an agent started with --id auto learns it at admission).
void set_log_agent_id(std::uint32_t id);

/// The format setup_logging() chose (text before it is called).
LogFormat log_format();

/// One record as a line without its newline; agent_id 0 shows no id (json: null).
std::string format_log_line(LogFormat format, const std::string& process, std::uint32_t agent_id, long pid,
                            std::chrono::system_clock::time_point time, const std::string& level,
                            const std::string& message);

/// Writes the program's last line on an error: `text` and a newline in text format; in json a record at level error
/// whose message is `text`.
void write_exit_error(std::ostream& err, const std::string& text);

/// A stream whose every line becomes a log record of the default logger, at the level `level_of(line)` gives
/// ("info", "warn", "error"), after removing `prefix` from its start. For programs whose diagnostics are written to
/// a stream (marsala-monitor's).
class LogLineStream : public std::ostream {
 public:
  LogLineStream(std::string prefix, std::function<std::string(const std::string&)> level_of);
  ~LogLineStream() override;

 private:
  class Buffer;
  std::unique_ptr<Buffer> buffer_;
};

}  // namespace marsala::cli
