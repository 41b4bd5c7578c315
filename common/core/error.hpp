#pragma once
// The one error family: every broken contract (bad file, bad parameter, bad argument)
// throws a subclass of marsala::Error whose message says what and where.

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace marsala {

/// Root of every error the project throws on purpose.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// A file (terrain, scenario, image) is malformed; the message names file, line and problem.
class ParseError : public Error {
 public:
  /// `file`: path as given; `line`: 1-based line number, 0 when not line-oriented.
  ParseError(const std::string& file, int line, const std::string& problem)
      : Error(line > 0 ? fmt::format("{}:{}: {}", file, line, problem) : fmt::format("{}: {}", file, problem)),
        file_(file),
        line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

/// A parameter is out of its valid range or inconsistent (e.g. kappa <= 0, unknown name).
class InvalidArgument : public Error {
 public:
  explicit InvalidArgument(const std::string& what) : Error(what) {}
};

/// An input/output operation failed (cannot open, cannot write).
class IoError : public Error {
 public:
  explicit IoError(const std::string& what) : Error(what) {}
};

/// The publish/subscribe layer failed (participant, topic, reader or writer could not be made or used).
class BusError : public Error {
 public:
  explicit BusError(const std::string& what) : Error(what) {}
};

}  // namespace marsala
