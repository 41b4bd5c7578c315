#pragma once
// How every MARSala executable parses its command line: --help (on the program or a subcommand) prints help and
// exits 0; --version prints "<program> <version> (git <revision>)" (version.hpp) and exits 0; a usage error prints
// one line "<program>: <reason> (run with --help for usage)" and exits 2.
// Include it only from files that link marsala::cli.

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

// CLI11 2.1's pair conversion trips a false -Wmaybe-uninitialized at -O2; keep our own warnings on.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <CLI/CLI.hpp>
#pragma GCC diagnostic pop

#include "marsala/cli/version.hpp"

namespace marsala::cli {

/// Exit code of a usage error (unknown option, bad value, missing argument).
inline constexpr int kExitUsage = 2;

/// Where a process meets the others: vendor, domain and profile, from flags or the environment.
struct DdsOptions {
  std::string vendor = "cyclone";  ///< cyclone, fastdds (or inprocess, in tests)
  int domain = 0;                  ///< 0..232
  std::string profile;             ///< a profile file of the vendor; empty: bus::resolve_profile()'s default
  std::string security;            ///< DDS Security folder (deploy/security/make-identities.sh); empty: unsecured
  std::string identity;            ///< the identity in it; empty: the program's own (world, monitor, agent-<id>)
  std::vector<std::string> peers;  ///< hosts to discover by unicast, no multicast (--peers); empty: the profile's way
};

/// True when `text` is a dotted-quad IPv4 address (four decimal numbers 0..255) or a host name (labels of letters,
/// digits and '-', none starting or ending with '-', at most 63 characters each and 253 in all, not all digits).
inline bool is_peer_address(const std::string& text) {
  if (text.empty() || text.size() > 253 || text.front() == '.' || text.back() == '.') return false;
  std::vector<std::string> labels(1);
  for (const char c : text) {
    if (c == '.')
      labels.emplace_back();
    else if (std::isalnum(static_cast<unsigned char>(c)) || c == '-')
      labels.back() += c;
    else
      return false;
  }
  bool numeric = true;
  for (const std::string& label : labels) {
    if (label.empty() || label.size() > 63 || label.front() == '-' || label.back() == '-') return false;
    numeric = numeric && label.find_first_not_of("0123456789") == std::string::npos;
  }
  if (!numeric) return true;
  if (labels.size() != 4) return false;
  for (const std::string& label : labels)
    if (label.size() > 3 || std::stoi(label) > 255 || (label.size() > 1 && label.front() == '0')) return false;
  return true;
}

/// Every element of --peers: an IPv4 address or a host name (is_peer_address()), else "'<text>' is not ...".
inline CLI::Validator peer_address() {
  return CLI::Validator(
      [](std::string& text) {
        return is_peer_address(text)
                   ? std::string()
                   : fmt::format("'{}' is not an IPv4 address or a host name (ADDR[,ADDR...], no port)", text);
      },
      "ADDR");
}

/// Adds --dds, --domain, --dds-config, --security, --identity and --peers to `app`, each also read from the
/// environment (MARSALA_DDS, MARSALA_DOMAIN, MARSALA_DDS_CONFIG, MARSALA_SECURITY, MARSALA_IDENTITY, MARSALA_PEERS)
/// when the flag is not given: flags win (docs/runtime.md#dds-profiles).
inline void add_dds_options(CLI::App& app, DdsOptions& options) {
  app.add_option("--dds", options.vendor, "DDS vendor: cyclone, fastdds (inprocess: tests only)")
      ->check(CLI::IsMember({"cyclone", "fastdds", "inprocess"}))
      ->envname("MARSALA_DDS")
      ->capture_default_str();
  app.add_option("--domain", options.domain, "DDS domain id")
      ->check(CLI::Range(0, 232))
      ->envname("MARSALA_DOMAIN")
      ->capture_default_str();
  app.add_option("--dds-config", options.profile,
                 "a DDS profile file of that vendor, e.g. deploy/dds/cyclone-lan.xml for a network (default: the\n"
                 "vendor's CYCLONEDDS_URI / FASTRTPS_DEFAULT_PROFILES_FILE, else the shipped loopback profile)")
      ->envname("MARSALA_DDS_CONFIG");
  app.add_option("--security", options.security,
                 "DDS Security: a folder made by deploy/security/make-identities.sh (authentication, access control,\n"
                 "encryption; every process of the run must use one; docs/runtime.md#security)")
      ->envname("MARSALA_SECURITY");
  app.add_option(
         "--identity", options.identity,
         "with --security: the identity to use (file stem in the folder; default: world, monitor or agent-<id>)")
      ->envname("MARSALA_IDENTITY");
  app.add_option("--peers", options.peers,
                 "discover by unicast only, no multicast: the hosts to probe, IPv4 addresses or names; the world's\n"
                 "address is enough for agents and monitors (default profile: deploy/dds/<vendor>-unicast.xml, every\n"
                 "interface; docs/runtime.md#peers)")
      ->delimiter(',')
      ->type_name("ADDR[,ADDR...]")
      ->check(peer_address())
      ->envname("MARSALA_PEERS");
}

/// A whole number >= 1, e.g. a "every K steps" (CLI11's PositiveNumber explains a 0 with a range of 300 digits).
inline CLI::Validator at_least_one() {
  return CLI::Validator(
      [](std::string& text) {
        const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
        return digits && text.find_first_not_of('0') != std::string::npos
                   ? std::string()
                   : fmt::format("must be a whole number of at least 1, not {}", text);
      },
      ">= 1");
}

/// A validator taking finite numbers for which `in_range` holds; anything else gets "must be <expected>, not '<text>'".
/// CLI11's Range, PositiveNumber and NonNegativeNumber let "nan" through (every comparison with it is false), so every
/// floating-point option uses one of the validators below.
inline CLI::Validator finite_number(std::function<bool(double)> in_range, const std::string& expected,
                                    const std::string& description) {
  return CLI::Validator(
      [in_range = std::move(in_range), expected](std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        return !text.empty() && *end == '\0' && std::isfinite(v) && in_range(v)
                   ? std::string()
                   : fmt::format("must be {}, not '{}'", expected, text);
      },
      description);
}

/// A finite number in [lo, hi]; `what` names it (e.g. "a number of seconds") and `meaning` follows the range, e.g.
/// " (0: wait forever)".
inline CLI::Validator number_within(double lo, double hi, const std::string& what = "a number",
                                    const std::string& meaning = "") {
  return finite_number([lo, hi](double v) { return v >= lo && v <= hi; },
                       fmt::format("{} from {} to {}{}", what, lo, hi, meaning), fmt::format("X in [{}, {}]", lo, hi));
}

/// A finite number of seconds in [lo, hi]; `meaning` is added to the message, e.g. " (0: wait forever)".
inline CLI::Validator seconds_within(double lo, double hi, const std::string& meaning = "") {
  return number_within(lo, hi, "a number of seconds", meaning);
}

/// A finite number above 0 (a length, a slope): CLI::PositiveNumber without "nan" and "inf".
inline CLI::Validator positive_number() {
  return finite_number([](double v) { return v > 0.0; }, "a finite number above 0", "X > 0");
}

/// A finite number of at least 0: CLI::NonNegativeNumber without "nan" and "inf".
inline CLI::Validator non_negative_number() {
  return finite_number([](double v) { return v >= 0.0; }, "a finite number of at least 0", "X >= 0");
}

/// Parses argv into `app`; returns nullopt when the program should go on, else the exit code to return now.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv,
                                             const std::string& program, std::ostream& out, std::ostream& err) {
  app.set_version_flag("--version", version_text(program), "print the version and the git revision, then exit");
  try {
    app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::CallForVersion& e) {
    out << e.what() << "\n";
    return 0;
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
    err << fmt::format("{}: {} (run with --help for usage)\n", program, e.what());
    return kExitUsage;
  }
}

}  // namespace marsala::cli
