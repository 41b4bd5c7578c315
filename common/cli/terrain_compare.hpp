#pragma once
// `marsala-terrain compare BELIEVED TRUE`: a robot's map (an agent's --dump-map, NODATA = unknown) against the true
// terrain (the run's terrain_final.asc): known cells, absolute height error over them, cells believed passable for a
// robot body that are not (terrain/map_comparison.hpp; docs/runtime.md#seeing-the-map). Include it only from files that
// link marsala::cli.

#include <ostream>
#include <string>
#include <vector>

#include "marsala/cli/command_line.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/types.hpp"

namespace marsala::cli {

/// Bad input of compare (a file missing, malformed, holding NaN, grids that differ, a scenario or robot type that
/// does not give a body): reported as one line naming the file, exit 2.
class InputError : public Error {
 public:
  explicit InputError(const std::string& what) : Error(what) {}
};

/// The compare subcommand: its options (define_compare binds them) and its CLI11 subcommand.
struct CompareCommand {
  CLI::App* cmd = nullptr;
  std::string believed_path;           ///< the robot's map (.asc; NODATA cells unknown)
  std::string true_path;               ///< the true terrain (.asc, every cell known)
  NavigabilityParams body;             ///< the body "passable" is judged for (default: ramp.pbtxt's builder)
  std::string scenario_path;           ///< or the body of a robot type of this scenario
  std::string robot_type;              ///< that type's name (default: the scenario's only type)
  std::vector<std::string> overrides;  ///< --set FIELD=VALUE on the scenario, as the run had them
  bool json = false;                   ///< one JSON object instead of text
};

/// Adds the compare subcommand to `app`, bound to `c` (which must outlive the parse).
void define_compare(CLI::App& app, CompareCommand& c);

/// Runs it: the comparison as text or JSON on `out`. Throws InputError for bad input.
void run_compare(const CompareCommand& c, std::ostream& out);

}  // namespace marsala::cli
