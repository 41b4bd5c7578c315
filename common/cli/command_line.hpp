#pragma once
// How every MARSala executable parses its command line: --help (on the program or a subcommand) prints help and
// exits 0; a usage error prints one line "<program>: <reason> (run with --help for usage)" and exits 2.
// Header-only; include it only from files that link CLI11::CLI11.

#include <optional>
#include <ostream>
#include <string>

// CLI11 2.1's pair conversion trips a false -Wmaybe-uninitialized at -O2; keep our own warnings on.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <CLI/CLI.hpp>
#pragma GCC diagnostic pop

namespace marsala::cli {

/// Exit code of a usage error (unknown option, bad value, missing argument).
inline constexpr int kExitUsage = 2;

/// Parses argv into `app`; returns nullopt when the program should go on, else the exit code to return now.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv,
                                             const std::string& program, std::ostream& out, std::ostream& err) {
  try {
    app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::CallForAllHelp&) {
    out << app.help("", CLI::AppFormatMode::All);
    return 0;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {  // --help, raised by the program or by the subcommand it was given to
      const std::vector<CLI::App*> subcommands = app.get_subcommands();
      if (subcommands.empty()) out << app.help();
      for (const CLI::App* sub : subcommands) out << sub->help();
      return 0;
    }
    err << program << ": " << e.what() << " (run with --help for usage)\n";
    return kExitUsage;
  }
}

}  // namespace marsala::cli
