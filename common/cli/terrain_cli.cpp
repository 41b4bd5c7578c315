#include "marsala/cli/terrain_cli.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "marsala/cli/command_line.hpp"
#include "marsala/cli/terrain_compare.hpp"
#include "marsala/core/deposition.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/core/route_sites.hpp"
#include "marsala/render/perspective.hpp"
#include "marsala/render/png_writer.hpp"
#include "marsala/render/terrain_renderer.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/terrain/generators.hpp"
#include "marsala/terrain/geotiff_import.hpp"
#include "marsala/terrain/resample.hpp"
#include "marsala/terrain/terrain_stats.hpp"

namespace marsala::cli {
namespace {

constexpr int kExitData = 1;

/// A usage error found after parsing (e.g. a bad --param); reported with exit code 2.
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& what) : Error(what) {}
};

bool has_tiff_extension(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return std::tolower(ch); });
  auto ends_with = [&](const std::string& suffix) {
    return lower.size() >= suffix.size() && lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends_with(".tif") || ends_with(".tiff");
}

Heightmap load_terrain(const std::string& path, bool fill_nodata) {
  if (has_tiff_extension(path)) return terrain::read_geotiff(path, terrain::GeoTiffOptions{fill_nodata});
  return terrain::read_asc(path, terrain::AscReadOptions{fill_nodata});
}

Heightmap mask_as_heights(const CellMask& mask, const GridGeometry& geometry) {
  return Heightmap(geometry, mask.cast<double>().eval());
}

long long count(const CellMask& mask) { return mask.cast<long long>().sum(); }

/// `part` of `whole` in percent, one decimal.
double percent(long long part, long long whole) { return whole > 0 ? 100.0 * part / whole : 0.0; }

/// The whole of `text` as a number (std::stod, nothing left over), or nullopt.
std::optional<double> parse_number(const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used == 0 || used != text.size()) return std::nullopt;
  return value;
}

/// Parses "key=value" pairs of --param into a map; a malformed pair is a usage error.
std::map<std::string, double> parse_params(const std::vector<std::string>& pairs) {
  std::map<std::string, double> params;
  for (const std::string& pair : pairs) {
    const auto eq = pair.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError(fmt::format("--param expects KEY=VALUE, got '{}'", pair));
    const std::string key = pair.substr(0, eq);
    const std::string text = pair.substr(eq + 1);
    const std::optional<double> value = parse_number(text);
    if (!value) throw UsageError(fmt::format("--param {}: '{}' is not a number", key, text));
    if (!params.emplace(key, *value).second) throw UsageError(fmt::format("--param {} is given twice", key));
  }
  return params;
}

std::string methods_help() {
  std::string help = "Methods and their --param keys:\n";
  for (const std::string& name : terrain::generator_names()) {
    help += fmt::format("  {}\n", name);
    for (const std::string& line : terrain::generator_parameter_help(name)) help += fmt::format("    {}\n", line);
  }
  return help;
}

/// Adds --kappa/--eps/--delta with range checks to a subcommand.
void add_navigability_options(CLI::App& cmd, NavigabilityParams& params, bool required) {
  auto* kappa = cmd.add_option("--kappa", params.kappa, "maximum climbable slope, rise over run [m/m]")
                    ->check(positive_number());
  auto* eps =
      cmd.add_option("--eps", params.eps_m, "largest discontinuity per body length [m]")->check(non_negative_number());
  auto* delta = cmd.add_option("--delta", params.delta_m, "robot body length [m]")->check(positive_number());
  if (required) {
    kappa->required();
    eps->required();
    delta->required();
  } else {
    kappa->capture_default_str();
    eps->capture_default_str();
    delta->capture_default_str();
  }
}

CellIndex to_cell(const std::pair<int, int>& rc) { return CellIndex{rc.first, rc.second}; }

void check_origin(const Heightmap& map, CellIndex origin) {
  if (!map.contains(origin))
    throw InvalidArgument(fmt::format("origin cell {} is off the {} x {} grid", origin, map.rows(), map.cols()));
}

/// One route to plan: from and to in the terrain's frame [m].
struct RouteQuery {
  Position from, to;
};

/// The routes of --pairs FILE: one "FROM_X FROM_Y TO_X TO_Y" per line [m]; blank lines and '#' comments skipped.
std::vector<RouteQuery> read_route_pairs(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw UsageError(fmt::format("--pairs {}: cannot be read", path));
  std::vector<RouteQuery> queries;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream s(line);
    std::vector<double> v;
    std::string word;
    while (s >> word) {
      const std::optional<double> value = parse_number(word);
      if (!value || !std::isfinite(*value))
        throw UsageError(fmt::format("{}:{}: '{}' is not a finite number", path, number, word));
      v.push_back(*value);
    }
    if (v.empty()) continue;
    if (v.size() != 4)
      throw UsageError(fmt::format("{}:{}: expected FROM_X FROM_Y TO_X TO_Y, got {} numbers", path, number, v.size()));
    queries.push_back({{v[0], v[1]}, {v[2], v[3]}});
  }
  if (queries.empty()) throw UsageError(fmt::format("--pairs {} holds no route", path));
  return queries;
}

/// The cell under a point given on the command line; off the terrain or not finite is a usage error.
CellIndex cell_under(const Heightmap& map, Position p, const std::string& what) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y))
    throw UsageError(fmt::format("{} {} is not a finite point", what, p));
  const auto cell = map.cell_at(p);
  if (!cell) {
    const auto& g = map.geometry();
    throw UsageError(fmt::format("{} {} is off the terrain (x {} .. {} m, y {} .. {} m)", what, p,
                                 g.xll_m, g.xll_m + g.cols * g.cell_size_m, g.yll_m, g.yll_m + g.rows * g.cell_size_m));
  }
  return *cell;
}

/// `map` as import makes it: cropped (X0 Y0 W H [m], when given), resampled (when the cell size is > 0), its lowest
/// cell shifted to 0 m (zero_base).
Heightmap import_terrain(Heightmap map, const std::vector<double>& crop, double cell_size_m, bool zero_base) {
  if (!crop.empty()) map = terrain::crop(map, crop[0], crop[1], crop[2], crop[3]);
  if (cell_size_m > 0.0) map = terrain::resample_bilinear(map, cell_size_m);
  if (zero_base) map.heights().array() -= map.min_height();
  return map;
}

/// Labels the 8-connected components of the mask's 1-cells 1, 2, ... in row-major order of their first cell; 0 off
/// the mask. Two occupiable cells are navigable from one another exactly when they share a label.
Eigen::MatrixXi component_labels(const CellMask& mask) {
  Eigen::MatrixXi label = Eigen::MatrixXi::Zero(mask.rows(), mask.cols());
  int next = 0;
  std::vector<CellIndex> stack;
  for (int r = 0; r < mask.rows(); ++r)
    for (int c = 0; c < mask.cols(); ++c) {
      if (mask(r, c) == 0 || label(r, c) != 0) continue;
      label(r, c) = ++next;
      stack.push_back({r, c});
      while (!stack.empty()) {
        const CellIndex p = stack.back();
        stack.pop_back();
        for (int dr = -1; dr <= 1; ++dr)
          for (int dc = -1; dc <= 1; ++dc) {
            const int rr = p.row + dr, cc = p.col + dc;
            if (rr < 0 || cc < 0 || rr >= mask.rows() || cc >= mask.cols()) continue;
            if (mask(rr, cc) == 0 || label(rr, cc) != 0) continue;
            label(rr, cc) = next;
            stack.push_back({rr, cc});
          }
      }
    }
  return label;
}

/// The value `v` printed with `digits` decimals has (machine outputs keep the precision their text always had).
double rounded(double v, int digits) { return std::strtod(fmt::format("{:.{}f}", v, digits).c_str(), nullptr); }

/// Adds the input terrain argument every subcommand that reads one has.
void add_input(CLI::App& cmd, std::string& path, const std::string& help = "input .asc or .tif") {
  cmd.add_option("input", path, help)->required()->check(CLI::ExistingFile);
}

/// Adds --fill-nodata.
void add_fill_nodata(CLI::App& cmd, bool& fill, const char* help = "fill NODATA cells instead of failing") {
  cmd.add_flag("--fill-nodata", fill, help);
}

/// How import and route prepare a terrain: import_terrain()'s crop (X0 Y0 W H [m], or empty), cell size [m] (0: as
/// read) and zero base.
struct TerrainPreparation {
  std::vector<double> crop;
  double cell_size_m = 0.0;
  bool zero_base = false;
};

/// The generate subcommand: its options (define_generate binds them) and its CLI11 subcommand.
struct GenerateCommand {
  CLI::App* cmd = nullptr;
  terrain::GeneratorSpec spec;
  std::string method;
  std::string out_path;
  std::vector<std::string> param_pairs;
};

void define_generate(CLI::App& app, GenerateCommand& c) {
  c.cmd = app.add_subcommand("generate", "generate a seeded, deterministic terrain");
  c.cmd->add_option("--method", c.method, "generator name (see below)")->required();
  c.cmd->add_option("--seed", c.spec.seed, "random seed")->capture_default_str();
  c.cmd->add_option("--rows", c.spec.rows, "rows")->required()->check(CLI::Range(1, 1 << 16));
  c.cmd->add_option("--cols", c.spec.cols, "columns")->required()->check(CLI::Range(1, 1 << 16));
  c.cmd->add_option("--cell-size", c.spec.cell_size_m, "cell size [m]")->required()->check(positive_number());
  c.cmd->add_option("--param", c.param_pairs, "method parameter KEY=VALUE (repeatable)");
  c.cmd->add_option("-o,--output", c.out_path, "output .asc")->required();
  c.cmd->footer(methods_help());
}

void run_generate(GenerateCommand& c, std::ostream& out) {
  c.spec.params = parse_params(c.param_pairs);
  Heightmap map;
  try {
    map = terrain::generate_terrain(c.method, c.spec);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());  // unknown method or parameter: the command line is wrong
  }
  terrain::write_asc(map, c.out_path);
  out << fmt::format("generated {} {} x {} at {:.6g} m, heights {:.6g} .. {:.6g} m -> {}\n", c.method, map.rows(),
                     map.cols(), map.cell_size_m(), map.min_height(), map.max_height(), c.out_path);
}

/// The import subcommand: its options (define_import binds them) and its CLI11 subcommand.
struct ImportCommand {
  CLI::App* cmd = nullptr;
  std::string in_path;
  std::string out_path;
  TerrainPreparation preparation;
  bool fill_nodata = false;
};

void define_import(CLI::App& app, ImportCommand& c) {
  c.cmd = app.add_subcommand("import", "import a GeoTIFF (or .asc) with optional crop and resampling");
  add_input(*c.cmd, c.in_path, "input .tif/.tiff or .asc");
  c.cmd->add_option("-o,--output", c.out_path, "output .asc")->required();
  c.cmd->add_option("--crop", c.preparation.crop, "crop X0 Y0 W H [m], in the imported local frame (lower-left = 0, 0)")
      ->expected(4);
  c.cmd->add_option("--cell-size", c.preparation.cell_size_m, "resample bilinearly to this cell size [m]")
      ->check(positive_number());
  add_fill_nodata(*c.cmd, c.fill_nodata, "fill NODATA cells from their valid neighbours instead of failing");
  c.cmd->add_flag("--zero-base", c.preparation.zero_base, "shift heights so that the lowest cell is at 0 m");
}

void run_import(const ImportCommand& c, std::ostream& out) {
  const TerrainPreparation& p = c.preparation;
  const Heightmap map = import_terrain(load_terrain(c.in_path, c.fill_nodata), p.crop, p.cell_size_m, p.zero_base);
  // The written grid starts its own local frame at (0, 0).
  GridGeometry local = map.geometry();
  local.xll_m = 0.0;
  local.yll_m = 0.0;
  terrain::write_asc(Heightmap(local, map.heights()), c.out_path);
  out << fmt::format("imported {}: {} x {} at {:.6g} m -> {}\n", c.in_path, map.rows(), map.cols(), map.cell_size_m(),
                     c.out_path);
}

/// The info subcommand: its options (define_info binds them) and its CLI11 subcommand.
struct InfoCommand {
  CLI::App* cmd = nullptr;
  std::string in_path;
  bool fill_nodata = false;
};

void define_info(CLI::App& app, InfoCommand& c) {
  c.cmd = app.add_subcommand("info", "print size, cell size, extent, height range and mean slope");
  add_input(*c.cmd, c.in_path);
  add_fill_nodata(*c.cmd, c.fill_nodata);
}

void run_info(const InfoCommand& c, std::ostream& out) {
  const Heightmap map = load_terrain(c.in_path, c.fill_nodata);
  const terrain::TerrainStats s = terrain::compute_terrain_stats(map);
  const auto& g = map.geometry();
  // Six significant digits: a summary for people.
  out << fmt::format(
      "file        {}\n"
      "size        {} rows x {} cols ({} cells)\n"
      "cell size   {:.6g} m\n"
      "extent      x {:.6g} .. {:.6g} m, y {:.6g} .. {:.6g} m ({:.6g} x {:.6g} m)\n"
      "height      {:.6g} .. {:.6g} m (mean {:.6g} m, relief {:.6g} m)\n"
      "mean slope  {:.6g} (rise over run; max {:.6g})\n",
      c.in_path, s.rows, s.cols, map.size(), s.cell_size_m, g.xll_m, g.xll_m + s.width_m, g.yll_m,
      g.yll_m + s.height_m, s.width_m, s.height_m, s.min_height_m, s.max_height_m, s.mean_height_m,
      s.max_height_m - s.min_height_m, s.mean_slope, s.max_slope);
}

/// The mars subcommand: its options (define_mars binds them) and its CLI11 subcommand.
struct MarsCommand {
  CLI::App* cmd = nullptr;
  std::string in_path;
  std::string out_path;
  double kappa = 0.0;
  bool write_gap = false;
  bool fill_nodata = false;
};

void define_mars(CLI::App& app, MarsCommand& c) {
  c.cmd = app.add_subcommand("mars", "write the MARS bound P_kappa[h] (or, with --gap, the MARS gap)");
  add_input(*c.cmd, c.in_path);
  c.cmd->add_option("--kappa", c.kappa, "maximum climbable slope, rise over run [m/m]")
      ->required()
      ->check(positive_number());
  c.cmd->add_option("-o,--output", c.out_path, "output .asc")->required();
  c.cmd->add_flag("--gap", c.write_gap, "write the gap P_kappa[h] - h instead of P_kappa[h]");
  add_fill_nodata(*c.cmd, c.fill_nodata);
}

void run_mars(const MarsCommand& c, std::ostream& out) {
  const Heightmap map = load_terrain(c.in_path, c.fill_nodata);
  const MarsProcessor processor(c.kappa);
  const Heightmap bound = processor.project(map);
  const Heightmap gap(map.geometry(), (bound.heights() - map.heights()).eval());
  terrain::write_asc(c.write_gap ? gap : bound, c.out_path);
  out << fmt::format("MARS at kappa {:.6g}: gap volume {:.6g} m^3, largest gap {:.6g} m -> {}\n", c.kappa,
                     deposition_target_volume(gap), gap.max_height(), c.out_path);
}

/// The navigable subcommand: its options (define_navigable binds them) and its CLI11 subcommand.
struct NavigableCommand {
  CLI::App* cmd = nullptr;
  std::string in_path;
  std::string out_path;
  NavigabilityParams params;
  std::pair<int, int> origin{0, 0};
  CLI::Option* origin_option = nullptr;
  bool write_occupiable = false;
  bool fill_nodata = false;
};

void define_navigable(CLI::App& app, NavigableCommand& c) {
  c.cmd = app.add_subcommand("navigable", "write 1 for navigable cells, 0 otherwise");
  add_input(*c.cmd, c.in_path);
  add_navigability_options(*c.cmd, c.params, true);
  c.origin_option = c.cmd->add_option("--origin-cell", c.origin, "origin cell ROW COL");
  c.cmd->add_option("-o,--output", c.out_path, "output .asc")->required();
  c.cmd->add_flag("--occupiable", c.write_occupiable, "write occupiability instead (no origin needed)");
  add_fill_nodata(*c.cmd, c.fill_nodata);
}

void run_navigable(const NavigableCommand& c, std::ostream& out) {
  const Heightmap map = load_terrain(c.in_path, c.fill_nodata);
  const NavigabilityProcessor processor(c.params);
  const CellMask occupiable = processor.occupiable(map);
  const long long cells = map.size();
  if (c.write_occupiable) {
    terrain::write_asc(mask_as_heights(occupiable, map.geometry()), c.out_path);
    out << fmt::format("occupiable {} of {} cells ({:.1f}%) -> {}\n", count(occupiable), cells,
                       percent(count(occupiable), cells), c.out_path);
    return;
  }
  if (c.origin_option->count() == 0) throw UsageError("navigable: --origin-cell ROW COL is required");
  const CellIndex origin = to_cell(c.origin);
  check_origin(map, origin);
  const CellMask reach = NavigabilityProcessor::navigable_from(occupiable, origin);
  terrain::write_asc(mask_as_heights(reach, map.geometry()), c.out_path);
  out << fmt::format("navigable from {}: {} of {} cells ({:.1f}%); occupiable {} -> {}\n", origin, count(reach), cells,
                     percent(count(reach), cells), count(occupiable), c.out_path);
  if (count(reach) == 0) out << "note: the origin cell is not occupiable, so nothing is navigable\n";
}

/// The render subcommand: its options (define_render binds them) and its CLI11 subcommand.
struct RenderCommand {
  CLI::App* cmd = nullptr;
  std::string in_path;
  std::string out_path;
  std::vector<std::pair<int, int>> origins;
  bool gap = false;
  std::string title;
  int max_size_px = 1024;
  NavigabilityParams params;
  bool fill_nodata = false;
};

void define_render(CLI::App& app, RenderCommand& c) {
  c.cmd = app.add_subcommand("render", "write a hillshaded, colour-mapped PNG with optional overlays");
  add_input(*c.cmd, c.in_path);
  c.cmd->add_option("-o,--output", c.out_path, "output .png")->required();
  c.cmd->add_option("--navigable-from", c.origins,
                    "overlay the region navigable from ROW COL (repeatable; give the input file first)");
  c.cmd->add_flag("--gap", c.gap, "overlay the MARS gap at --kappa");
  add_navigability_options(*c.cmd, c.params, false);
  c.cmd->add_option("--title", c.title, "title drawn above the picture");
  c.cmd->add_option("--max-size", c.max_size_px, "longest side of the terrain picture [px]")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  add_fill_nodata(*c.cmd, c.fill_nodata);
}

void run_render(const RenderCommand& c, std::ostream& out) {
  const Heightmap map = load_terrain(c.in_path, c.fill_nodata);
  render::RenderOptions options;
  options.title = c.title;
  options.max_size_px = c.max_size_px;
  if (!c.origins.empty()) {
    const NavigabilityProcessor processor(c.params);
    const CellMask occupiable = processor.occupiable(map);
    CellMask reach = CellMask::Zero(map.rows(), map.cols());
    for (const auto& rc : c.origins) {
      const CellIndex origin = to_cell(rc);
      check_origin(map, origin);
      reach = reach.cwiseMax(NavigabilityProcessor::navigable_from(occupiable, origin));
      options.markers.push_back(origin);
    }
    options.navigable = reach;
  }
  if (c.gap) options.gap = MarsProcessor(c.params.kappa).gap(map);
  render::write_png(render::render_terrain(map, options), c.out_path);
  out << fmt::format("rendered {} x {} -> {}\n", map.rows(), map.cols(), c.out_path);
}

/// The render3d subcommand: its options (define_render3d binds them) and its CLI11 subcommand.
struct Render3dCommand {
  CLI::App* cmd = nullptr;
  std::string in_path;
  std::string out_path;
  render::PerspectiveOptions view;
  std::string deposits_from;
  std::pair<int, int> size{1200, 800};
  bool fill_nodata = false;
};

void define_render3d(CLI::App& app, Render3dCommand& c) {
  c.cmd = app.add_subcommand(
      "render3d", "write a perspective view of a terrain (built material tinted with --deposits-from) as a PNG");
  add_input(*c.cmd, c.in_path, "input .asc or .tif (e.g. a run's terrain_final.asc)");
  c.cmd->add_option("-o,--output", c.out_path, "output .png")->required();
  c.cmd
      ->add_option("--deposits-from", c.deposits_from,
                   "the terrain before construction (e.g. terrain_initial.asc): cells raised since are tinted")
      ->check(CLI::ExistingFile);
  c.cmd
      ->add_option("--azimuth", c.view.azimuth_deg,
                   "where the camera stands, from the centre: 0 north, 90 east [deg]")
      ->capture_default_str();
  c.cmd->add_option("--elevation", c.view.elevation_deg, "camera height above the horizon, (0, 90] [deg]")
      ->capture_default_str();
  c.cmd->add_option("--exaggeration", c.view.vertical_exaggeration, "vertical exaggeration")->capture_default_str();
  c.cmd->add_option("--size", c.size, "picture size WIDTH HEIGHT [px]")->capture_default_str();
  c.cmd->add_option("--title", c.view.title, "title drawn in the top-left corner");
  add_fill_nodata(*c.cmd, c.fill_nodata);
}

void run_render3d(Render3dCommand& c, std::ostream& out) {
  const Heightmap map = load_terrain(c.in_path, c.fill_nodata);
  double built_m3 = 0.0;
  if (!c.deposits_from.empty()) {
    const Heightmap before = load_terrain(c.deposits_from, c.fill_nodata);
    if (before.rows() != map.rows() || before.cols() != map.cols())
      throw UsageError(fmt::format("--deposits-from {} is {} x {} cells, {} {} x {}", c.deposits_from, before.rows(),
                                   before.cols(), c.in_path, map.rows(), map.cols()));
    Heightmap deposit(map.geometry());
    for (int r = 0; r < map.rows(); ++r)
      for (int col = 0; col < map.cols(); ++col) {
        deposit(r, col) = std::max(0.0, map(r, col) - before(r, col));
        built_m3 += deposit(r, col) * map.cell_size_m() * map.cell_size_m();
      }
    c.view.deposit = std::move(deposit);
  }
  c.view.width_px = c.size.first;
  c.view.height_px = c.size.second;
  render::write_png(render::render_perspective(map, c.view), c.out_path);
  const std::string built = c.view.deposit ? fmt::format(" ({:.6g} m^3 built, tinted)", built_m3) : std::string();
  out << fmt::format("rendered a perspective view of {} x {} cells{} -> {}\n", map.rows(), map.cols(), built,
                     c.out_path);
}

/// The route subcommand: its options (define_route binds them) and its CLI11 subcommand.
struct RouteCommand {
  CLI::App* cmd = nullptr;
  std::string in_path;
  TerrainPreparation preparation;
  bool fill_nodata = false;
  NavigabilityParams payload;
  std::pair<double, double> from{0.0, 0.0};
  std::pair<double, double> to{0.0, 0.0};
  CLI::Option* from_option = nullptr;
  CLI::Option* to_option = nullptr;
  std::string pairs_path;
  double build_kappa = 0.0;
  double band_width_m = 0.0;
  double local_radius_m = 0.0;
  double min_depth_m = 0.0;
  double min_natural_m = -1.0;
  bool json = false;
};

void define_route(CLI::App& app, RouteCommand& c) {
  c.cmd = app.add_subcommand(
      "route",
      "plan the route builders would build for a payload (planner priced by the MARS gap, paper eq. 4-5) and list "
      "the construction sites along it");
  add_input(*c.cmd, c.in_path);
  c.cmd->add_option("--crop", c.preparation.crop, "crop X0 Y0 W H [m] in the input's frame (as a scenario's terrain.crop)")
      ->expected(4);
  c.cmd->add_option("--cell-size", c.preparation.cell_size_m, "resample bilinearly to this cell size [m]")
      ->check(positive_number());
  c.cmd->add_flag("--zero-base", c.preparation.zero_base, "shift heights so that the lowest cell is at 0 m");
  add_fill_nodata(*c.cmd, c.fill_nodata);
  add_navigability_options(*c.cmd, c.payload, true);
  c.from_option =
      c.cmd->add_option("--from", c.from, "where the route starts, X Y [m] in the terrain's frame (the base)");
  c.to_option = c.cmd->add_option("--to", c.to, "where it ends, X Y [m] (the target)");
  c.cmd->add_option("--pairs", c.pairs_path, "plan every route of FILE instead: one 'FROM_X FROM_Y TO_X TO_Y' a line")
      ->check(CLI::ExistingFile);
  c.cmd->add_option("--construction-kappa", c.build_kappa, "slope the builders build to [m/m] (default: --kappa)")
      ->check(positive_number());
  c.cmd->add_option("--width", c.band_width_m, "construction band width [m] (default: --delta)")
      ->check(positive_number());
  c.cmd
      ->add_option("--min-depth", c.min_depth_m,
                   "a route cell needs construction when its MARS gap is at least this [m], e.g. one cube layer")
      ->check(non_negative_number())
      ->capture_default_str();
  c.cmd
      ->add_option("--min-natural", c.min_natural_m,
                   "natural ground shorter than this does not separate two sites [m] (default: --delta)")
      ->check(non_negative_number());
  c.cmd
      ->add_option("--local-radius", c.local_radius_m,
                   "take each cell's MARS bound over the square of this half-side around it only, as a builder's local "
                   "map of its sensing range does [m]; 0: the whole terrain")
      ->check(non_negative_number())
      ->capture_default_str();
  c.cmd->add_flag("--json", c.json, "print JSON instead of text");
}

/// The routes the command line asks for: --pairs FILE, or --from and --to.
std::vector<RouteQuery> route_queries(const RouteCommand& c) {
  if (!c.pairs_path.empty()) {
    if (c.from_option->count() > 0 || c.to_option->count() > 0)
      throw UsageError("route: give either --pairs or --from and --to, not both");
    return read_route_pairs(c.pairs_path);
  }
  if (c.from_option->count() == 0 || c.to_option->count() == 0)
    throw UsageError("route: --from X Y and --to X Y (or --pairs FILE) are required");
  return {{{c.from.first, c.from.second}, {c.to.first, c.to.second}}};
}

/// One planned route with what the payload can do at its ends.
struct PlannedRoute {
  Position from, to;  ///< centres of the end cells [m]
  RouteSites sites;
  int from_region = 0, to_region = 0;  ///< payload regions of the ends (component_labels); 0: not occupiable
  bool from_occupiable() const { return from_region != 0; }
  bool to_occupiable() const { return to_region != 0; }
  bool navigable_now() const { return from_region != 0 && from_region == to_region; }
};

/// The route as text for people: head line, one line per site, the payload's ends.
std::string route_text(const PlannedRoute& p, const RouteSiteParams& site_params, double site_kappa,
                       double local_radius_m) {
  const RouteSites& r = p.sites;
  const std::string bound = local_radius_m > 0.0 ? fmt::format(", bound within {} m", local_radius_m) : std::string();
  std::string text =
      fmt::format("route {} -> {}: length {:.2f} m, MARS gap {:.2f} m^3 over a {:.6g} m band (kappa {:.6g}{}), {} "
                  "construction site{}\n",
                  p.from, p.to, r.length_m, r.band_volume_m3, site_params.width_m, site_kappa, bound, r.sites.size(),
                  r.sites.size() == 1 ? "" : "s");
  for (std::size_t k = 0; k < r.sites.size(); ++k)
    text += fmt::format("  site {}: {:.2f} .. {:.2f} m along, {:.2f} m^3, deepest gap {:.2f} m\n", k + 1,
                        r.sites[k].from_m, r.sites[k].to_m, r.sites[k].volume_m3, r.sites[k].max_gap_m);
  text += fmt::format("  payload: from {} (gap {:.3f} m), to {} (gap {:.3f} m), {} from one to the other\n",
                      p.from_occupiable() ? "occupiable" : "NOT occupiable", r.from_gap_m,
                      p.to_occupiable() ? "occupiable" : "NOT occupiable", r.to_gap_m,
                      p.navigable_now() ? "already navigable" : "not navigable");
  return text;
}

/// The route as a JSON object (route --json; deploy/search_routes.py reads it). Lengths, volumes and gaps keep the
/// decimals the text gives them.
nlohmann::ordered_json route_json(const PlannedRoute& p) {
  const RouteSites& r = p.sites;
  nlohmann::ordered_json sites = nlohmann::ordered_json::array();
  for (const RouteSite& s : r.sites)
    sites.push_back({{"from_m", rounded(s.from_m, 3)},
                     {"to_m", rounded(s.to_m, 3)},
                     {"volume_m3", rounded(s.volume_m3, 3)},
                     {"max_gap_m", rounded(s.max_gap_m, 3)}});
  return {{"from", {p.from.x, p.from.y}},
          {"to", {p.to.x, p.to.y}},
          {"length_m", rounded(r.length_m, 3)},
          {"volume_m3", rounded(r.band_volume_m3, 3)},
          {"band_cells", r.band_cells},
          {"from_occupiable", p.from_occupiable()},
          {"to_occupiable", p.to_occupiable()},
          {"from_region", p.from_region},
          {"to_region", p.to_region},
          {"navigable_now", p.navigable_now()},
          {"from_gap_m", rounded(r.from_gap_m, 4)},
          {"to_gap_m", rounded(r.to_gap_m, 4)},
          {"sites", std::move(sites)}};
}

void run_route(const RouteCommand& c, std::ostream& out) {
  const std::vector<RouteQuery> queries = route_queries(c);
  const TerrainPreparation& prep = c.preparation;
  const Heightmap map =
      import_terrain(load_terrain(c.in_path, c.fill_nodata), prep.crop, prep.cell_size_m, prep.zero_base);
  std::vector<std::pair<CellIndex, CellIndex>> cells;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const std::string which = queries.size() > 1 ? fmt::format(" (route {})", i + 1) : std::string();
    cells.push_back({cell_under(map, queries[i].from, fmt::format("--from{}", which)),
                     cell_under(map, queries[i].to, fmt::format("--to{}", which))});
  }
  RouteSiteParams site_params;
  const double site_kappa = c.build_kappa > 0.0 ? c.build_kappa : c.payload.kappa;
  site_params.width_m = c.band_width_m > 0.0 ? c.band_width_m : c.payload.delta_m;
  site_params.min_depth_m = c.min_depth_m;
  site_params.min_natural_m = c.min_natural_m >= 0.0 ? c.min_natural_m : c.payload.delta_m;
  const Heightmap gap = route_gap(map, site_kappa, c.local_radius_m);
  const Eigen::MatrixXi region = component_labels(NavigabilityProcessor(c.payload).occupiable(map));
  nlohmann::ordered_json routes = nlohmann::ordered_json::array();
  for (const auto& [from, to] : cells) {
    const PlannedRoute planned{map.cell_center(from), map.cell_center(to),
                               plan_route_sites(gap, from, to, site_params), region(from.row, from.col),
                               region(to.row, to.col)};
    if (c.json)
      routes.push_back(route_json(planned));
    else
      out << route_text(planned, site_params, site_kappa, c.local_radius_m);
  }
  if (!c.json) return;
  const GridGeometry& g = map.geometry();
  const nlohmann::ordered_json doc = {
      {"terrain",
       {{"rows", g.rows}, {"cols", g.cols}, {"cell_size_m", g.cell_size_m}, {"xll_m", g.xll_m}, {"yll_m", g.yll_m}}},
      {"construction_kappa", site_kappa},
      {"local_radius_m", c.local_radius_m},
      {"width_m", site_params.width_m},
      {"min_depth_m", site_params.min_depth_m},
      {"min_natural_m", site_params.min_natural_m},
      {"routes", std::move(routes)}};
  out << doc.dump() << "\n";
}

/// Every subcommand, defined on one CLI::App (which keeps pointers into this struct: it must not move).
struct TerrainCommands {
  GenerateCommand generate;
  ImportCommand import;
  InfoCommand info;
  MarsCommand mars;
  NavigableCommand navigable;
  RenderCommand render;
  Render3dCommand render3d;
  RouteCommand route;
  CompareCommand compare;
};

/// Runs the subcommand the command line chose.
void run_chosen(TerrainCommands& c, std::ostream& out) {
  if (*c.generate.cmd) run_generate(c.generate, out);
  else if (*c.import.cmd) run_import(c.import, out);
  else if (*c.info.cmd) run_info(c.info, out);
  else if (*c.mars.cmd) run_mars(c.mars, out);
  else if (*c.navigable.cmd) run_navigable(c.navigable, out);
  else if (*c.render.cmd) run_render(c.render, out);
  else if (*c.route.cmd) run_route(c.route, out);
  else if (*c.render3d.cmd) run_render3d(c.render3d, out);
  else if (*c.compare.cmd) run_compare(c.compare, out);
}

}  // namespace

int run_terrain_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "marsala-terrain: generate, import, inspect and render terrains; compute MARS and navigability; compare a\n"
      "robot's map with the true terrain.\n"
      "Heights are metres; files are ESRI ASCII grids (.asc); GeoTIFF (.tif) is accepted as input.",
      "marsala-terrain"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "help for every subcommand");
  TerrainCommands commands;
  define_generate(app, commands.generate);
  define_import(app, commands.import);
  define_info(app, commands.info);
  define_mars(app, commands.mars);
  define_navigable(app, commands.navigable);
  define_render(app, commands.render);
  define_render3d(app, commands.render3d);
  define_route(app, commands.route);
  define_compare(app, commands.compare);
  if (const auto code = parse_command_line(app, argc, argv, "marsala-terrain", out, err)) return *code;

  try {
    run_chosen(commands, out);
  } catch (const UsageError& e) {
    err << fmt::format("marsala-terrain: {} (run with --help for usage)\n", e.what());
    return kExitUsage;
  } catch (const InputError& e) {
    err << fmt::format("marsala-terrain: {}\n", e.what());
    return kExitUsage;
  } catch (const Error& e) {
    err << fmt::format("marsala-terrain: {}\n", e.what());
    return kExitData;
  } catch (const std::bad_alloc&) {
    err << "marsala-terrain: out of memory\n";
    return kExitData;
  }
  return 0;
}

}  // namespace marsala::cli
