#include "marsala/cli/terrain_compare.hpp"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "marsala/core/format.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/terrain/map_comparison.hpp"

namespace marsala::cli {
namespace {

/// A map file with NODATA as NaN; any problem is bad input naming the file (the reader's messages do).
Heightmap read_map(const std::string& path) {
  try {
    return terrain::read_asc(path, terrain::AscReadOptions{false, true});
  } catch (const Error& e) {
    throw InputError(e.what());
  }
}

/// The body of --scenario's --robot-type (or its only type).
NavigabilityParams scenario_body(const CompareCommand& c) {
  scenario::Scenario s;
  try {
    s = scenario::load_scenario(c.scenario_path, c.overrides);
  } catch (const Error& e) {
    throw InputError(e.what());
  }
  std::vector<std::string> names;
  for (const RobotType& t : s.robot_types) {
    if (t.name == c.robot_type || (c.robot_type.empty() && s.robot_types.size() == 1)) return t.body.navigability;
    names.push_back(t.name);
  }
  throw InputError(c.robot_type.empty() ? fmt::format("{} has several robot types ({}): give --robot-type",
                                                      c.scenario_path, fmt::join(names, ", "))
                                        : fmt::format("{} has no robot type '{}'; it has: {}", c.scenario_path,
                                                      c.robot_type, fmt::join(names, ", ")));
}

std::string comparison_text(const CompareCommand& c, const NavigabilityParams& body, const terrain::MapComparison& m) {
  const double wrong_percent =
      m.believed_passable > 0 ? 100.0 * static_cast<double>(m.believed_passable_not) / m.believed_passable : 0.0;
  return fmt::format(
      "believed   {}\n"
      "true       {}\n"
      "known      {} of {} cells ({:.1f} %)\n"
      "error      median {:.4f} m, p95 {:.4f} m, max {:.4f} m (absolute, over the known cells)\n"
      "passable   {} cells believed passable for kappa {}, delta {} m, eps {} m; {} of them ({:.1f} %) are not on the "
      "true map ({} cells passable there)\n",
      c.believed_path, c.true_path, m.known_cells, m.cells, 100.0 * m.known_fraction(), m.median_error_m, m.p95_error_m,
      m.max_error_m, m.believed_passable, body.kappa, body.delta_m, body.eps_m, m.believed_passable_not, wrong_percent,
      m.true_passable);
}

nlohmann::ordered_json comparison_json(const CompareCommand& c, const NavigabilityParams& body,
                                       const terrain::MapComparison& m) {
  return {{"believed", c.believed_path},
          {"true", c.true_path},
          {"body", {{"kappa", body.kappa}, {"delta_m", body.delta_m}, {"eps_m", body.eps_m}}},
          {"cells", m.cells},
          {"known_cells", m.known_cells},
          {"known_fraction", m.known_fraction()},
          {"median_error_m", m.median_error_m},
          {"p95_error_m", m.p95_error_m},
          {"max_error_m", m.max_error_m},
          {"believed_passable", m.believed_passable},
          {"believed_passable_not", m.believed_passable_not},
          {"true_passable", m.true_passable}};
}

}  // namespace

void define_compare(CLI::App& app, CompareCommand& c) {
  c.cmd = app.add_subcommand(
      "compare",
      "compare a robot's map (marsala-agent --dump-map: NODATA = unknown) with the true terrain (terrain_final.asc):\n"
      "known cells, median / p95 / max absolute height error over them, and the cells believed passable for a body\n"
      "(known, no unknown cell within delta/2, occupiable) that are not occupiable on the true map. Bad input (a file\n"
      "missing or malformed, NaN, grids that differ) exits 2.");
  c.cmd->add_option("believed", c.believed_path, "the robot's map, .asc")->required();
  c.cmd->add_option("true", c.true_path, "the true terrain, .asc (every cell known)")->required();
  auto* scenario = c.cmd->add_option("--scenario", c.scenario_path, "take the body of a robot type of this scenario");
  c.cmd->add_option("--robot-type", c.robot_type, "with --scenario: the type (default: its only one)")->needs(scenario);
  c.cmd->add_option("--set", c.overrides, "with --scenario: FIELD=VALUE, as the run had it (repeatable)")
      ->needs(scenario);
  for (CLI::Option* o :
       {c.cmd->add_option("--kappa", c.body.kappa, "body: maximum climbable slope, rise over run [m/m]")
            ->check(positive_number()),
        c.cmd->add_option("--eps", c.body.eps_m, "body: largest discontinuity per body length [m]")
            ->check(non_negative_number()),
        c.cmd->add_option("--delta", c.body.delta_m, "body: length [m]")->check(positive_number())})
    o->capture_default_str()->excludes(scenario);
  c.cmd->add_flag("--json", c.json, "print one JSON object instead of text");
}

void run_compare(const CompareCommand& c, std::ostream& out) {
  const NavigabilityParams body = c.scenario_path.empty() ? c.body : scenario_body(c);
  const Heightmap believed = read_map(c.believed_path);
  const Heightmap truth = read_map(c.true_path);
  for (int r = 0; r < truth.rows(); ++r)
    for (int col = 0; col < truth.cols(); ++col)
      if (std::isnan(truth(r, col)))
        throw InputError(
            fmt::format("{}: cell {} is NODATA: the true map must know every cell", c.true_path, CellIndex{r, col}));
  terrain::MapComparison m;
  try {
    m = terrain::compare_maps(believed, truth, body);
  } catch (const InvalidArgument& e) {
    throw InputError(fmt::format("{} against {}: {}", c.believed_path, c.true_path, e.what()));
  }
  if (c.json)
    out << comparison_json(c, body, m).dump() << "\n";
  else
    out << comparison_text(c, body, m);
}

}  // namespace marsala::cli
