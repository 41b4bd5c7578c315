#include "marsala/cli/terrain_cli.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "marsala/cli/command_line.hpp"
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

std::string percent(long long part, long long whole) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << (whole > 0 ? 100.0 * part / whole : 0.0) << "%";
  return s.str();
}

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
    if (eq == std::string::npos || eq == 0) throw UsageError("--param expects KEY=VALUE, got '" + pair + "'");
    const std::string key = pair.substr(0, eq);
    const std::string text = pair.substr(eq + 1);
    const std::optional<double> value = parse_number(text);
    if (!value) throw UsageError("--param " + key + ": '" + text + "' is not a number");
    if (!params.emplace(key, *value).second) throw UsageError("--param " + key + " is given twice");
  }
  return params;
}

std::string methods_help() {
  std::ostringstream s;
  s << "Methods and their --param keys:\n";
  for (const std::string& name : terrain::generator_names()) {
    s << "  " << name << "\n";
    for (const std::string& line : terrain::generator_parameter_help(name)) s << "    " << line << "\n";
  }
  return s.str();
}

/// Adds --kappa/--eps/--delta with range checks to a subcommand.
void add_navigability_options(CLI::App& cmd, NavigabilityParams& params, bool required) {
  auto* kappa = cmd.add_option("--kappa", params.kappa, "maximum climbable slope, rise over run [m/m]")
                    ->check(CLI::PositiveNumber);
  auto* eps =
      cmd.add_option("--eps", params.eps_m, "largest discontinuity per body length [m]")->check(CLI::NonNegativeNumber);
  auto* delta = cmd.add_option("--delta", params.delta_m, "robot body length [m]")->check(CLI::PositiveNumber);
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
  if (!in) throw UsageError("--pairs " + path + ": cannot be read");
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
  if (queries.empty()) throw UsageError("--pairs " + path + " holds no route");
  return queries;
}

/// The cell under a point given on the command line; off the terrain or not finite is a usage error.
CellIndex cell_under(const Heightmap& map, Position p, const std::string& what) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y))
    throw UsageError(fmt::format("{} ({}, {}) m is not a finite point", what, p.x, p.y));
  const auto cell = map.cell_at(p);
  if (!cell) {
    const auto& g = map.geometry();
    throw UsageError(fmt::format("{} ({}, {}) m is off the terrain (x {} .. {} m, y {} .. {} m)", what, p.x, p.y,
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

/// The shortest text that reads back as v (cell centres such as 206.125 m stay exact in --json).
std::string shortest(double v) { return fmt::format("{}", v); }

std::string fixed(double v, int digits) { return fmt::format("{:.{}f}", v, digits); }

}  // namespace

int run_terrain_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "marsala-terrain: generate, import, inspect and render terrains; compute MARS and navigability.\n"
      "Heights are metres; files are ESRI ASCII grids (.asc); GeoTIFF (.tif) is accepted as input.",
      "marsala-terrain"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "help for every subcommand");

  // generate
  terrain::GeneratorSpec spec;
  std::string method;
  std::string out_path;
  std::vector<std::string> param_pairs;
  auto* generate = app.add_subcommand("generate", "generate a seeded, deterministic terrain");
  generate->add_option("--method", method, "generator name (see below)")->required();
  generate->add_option("--seed", spec.seed, "random seed")->capture_default_str();
  generate->add_option("--rows", spec.rows, "rows")->required()->check(CLI::Range(1, 1 << 16));
  generate->add_option("--cols", spec.cols, "columns")->required()->check(CLI::Range(1, 1 << 16));
  generate->add_option("--cell-size", spec.cell_size_m, "cell size [m]")->required()->check(CLI::PositiveNumber);
  generate->add_option("--param", param_pairs, "method parameter KEY=VALUE (repeatable)");
  generate->add_option("-o,--output", out_path, "output .asc")->required();
  generate->footer(methods_help());

  // import
  std::string in_path;
  std::vector<double> crop;
  double target_cell_size = 0.0;
  bool fill_nodata = false;
  bool zero_base = false;
  auto* import = app.add_subcommand("import", "import a GeoTIFF (or .asc) with optional crop and resampling");
  import->add_option("input", in_path, "input .tif/.tiff or .asc")->required()->check(CLI::ExistingFile);
  import->add_option("-o,--output", out_path, "output .asc")->required();
  import->add_option("--crop", crop, "crop X0 Y0 W H [m], in the imported local frame (lower-left = 0, 0)")
      ->expected(4);
  import->add_option("--cell-size", target_cell_size, "resample bilinearly to this cell size [m]")
      ->check(CLI::PositiveNumber);
  import->add_flag("--fill-nodata", fill_nodata, "fill NODATA cells from their valid neighbours instead of failing");
  import->add_flag("--zero-base", zero_base, "shift heights so that the lowest cell is at 0 m");

  // info
  auto* info = app.add_subcommand("info", "print size, cell size, extent, height range and mean slope");
  info->add_option("input", in_path, "input .asc or .tif")->required()->check(CLI::ExistingFile);
  info->add_flag("--fill-nodata", fill_nodata, "fill NODATA cells instead of failing");

  // mars
  double kappa = 0.0;
  bool write_gap = false;
  auto* mars = app.add_subcommand("mars", "write the MARS bound P_kappa[h] (or, with --gap, the MARS gap)");
  mars->add_option("input", in_path, "input .asc or .tif")->required()->check(CLI::ExistingFile);
  mars->add_option("--kappa", kappa, "maximum climbable slope, rise over run [m/m]")
      ->required()
      ->check(CLI::PositiveNumber);
  mars->add_option("-o,--output", out_path, "output .asc")->required();
  mars->add_flag("--gap", write_gap, "write the gap P_kappa[h] - h instead of P_kappa[h]");
  mars->add_flag("--fill-nodata", fill_nodata, "fill NODATA cells instead of failing");

  // navigable
  NavigabilityParams nav_params;
  std::pair<int, int> origin{0, 0};
  bool write_occupiable = false;
  auto* navigable = app.add_subcommand("navigable", "write 1 for navigable cells, 0 otherwise");
  navigable->add_option("input", in_path, "input .asc or .tif")->required()->check(CLI::ExistingFile);
  add_navigability_options(*navigable, nav_params, true);
  auto* origin_option = navigable->add_option("--origin-cell", origin, "origin cell ROW COL");
  navigable->add_option("-o,--output", out_path, "output .asc")->required();
  navigable->add_flag("--occupiable", write_occupiable, "write occupiability instead (no origin needed)");
  navigable->add_flag("--fill-nodata", fill_nodata, "fill NODATA cells instead of failing");

  // render
  std::vector<std::pair<int, int>> render_origins;
  bool render_gap = false;
  std::string title;
  int max_size_px = 1024;
  NavigabilityParams render_params;
  auto* render = app.add_subcommand("render", "write a hillshaded, colour-mapped PNG with optional overlays");
  render->add_option("input", in_path, "input .asc or .tif")->required()->check(CLI::ExistingFile);
  render->add_option("-o,--output", out_path, "output .png")->required();
  render->add_option("--navigable-from", render_origins,
                     "overlay the region navigable from ROW COL (repeatable; give the input file first)");
  render->add_flag("--gap", render_gap, "overlay the MARS gap at --kappa");
  add_navigability_options(*render, render_params, false);
  render->add_option("--title", title, "title drawn above the picture");
  render->add_option("--max-size", max_size_px, "longest side of the terrain picture [px]")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  render->add_flag("--fill-nodata", fill_nodata, "fill NODATA cells instead of failing");

  // render3d
  render::PerspectiveOptions view;
  std::string deposits_from;
  std::pair<int, int> view_size{1200, 800};
  auto* render3d = app.add_subcommand(
      "render3d", "write a perspective view of a terrain (built material tinted with --deposits-from) as a PNG");
  render3d->add_option("input", in_path, "input .asc or .tif (e.g. a run's terrain_final.asc)")
      ->required()
      ->check(CLI::ExistingFile);
  render3d->add_option("-o,--output", out_path, "output .png")->required();
  render3d
      ->add_option("--deposits-from", deposits_from,
                   "the terrain before construction (e.g. terrain_initial.asc): cells raised since are tinted")
      ->check(CLI::ExistingFile);
  render3d
      ->add_option("--azimuth", view.azimuth_deg, "where the camera stands, from the centre: 0 north, 90 east [deg]")
      ->capture_default_str();
  render3d->add_option("--elevation", view.elevation_deg, "camera height above the horizon, (0, 90] [deg]")
      ->capture_default_str();
  render3d->add_option("--exaggeration", view.vertical_exaggeration, "vertical exaggeration")->capture_default_str();
  render3d->add_option("--size", view_size, "picture size WIDTH HEIGHT [px]")->capture_default_str();
  render3d->add_option("--title", view.title, "title drawn in the top-left corner");
  render3d->add_flag("--fill-nodata", fill_nodata, "fill NODATA cells instead of failing");

  // route
  std::pair<double, double> route_from{0.0, 0.0}, route_to{0.0, 0.0};
  std::string pairs_path;
  NavigabilityParams payload;
  double build_kappa = 0.0, band_width = 0.0, local_radius = 0.0, min_depth = 0.0, min_natural = -1.0;
  bool route_json = false;
  auto* route = app.add_subcommand(
      "route",
      "plan the route builders would build for a payload (planner priced by the MARS gap, paper eq. 4-5) and list "
      "the construction sites along it");
  route->add_option("input", in_path, "input .asc or .tif")->required()->check(CLI::ExistingFile);
  route->add_option("--crop", crop, "crop X0 Y0 W H [m] in the input's frame (as a scenario's terrain.crop)")
      ->expected(4);
  route->add_option("--cell-size", target_cell_size, "resample bilinearly to this cell size [m]")
      ->check(CLI::PositiveNumber);
  route->add_flag("--zero-base", zero_base, "shift heights so that the lowest cell is at 0 m");
  route->add_flag("--fill-nodata", fill_nodata, "fill NODATA cells instead of failing");
  add_navigability_options(*route, payload, true);
  auto* from_option =
      route->add_option("--from", route_from, "where the route starts, X Y [m] in the terrain's frame (the base)");
  auto* to_option = route->add_option("--to", route_to, "where it ends, X Y [m] (the target)");
  route->add_option("--pairs", pairs_path, "plan every route of FILE instead: one 'FROM_X FROM_Y TO_X TO_Y' a line")
      ->check(CLI::ExistingFile);
  route->add_option("--construction-kappa", build_kappa, "slope the builders build to [m/m] (default: --kappa)")
      ->check(CLI::PositiveNumber);
  route->add_option("--width", band_width, "construction band width [m] (default: --delta)")
      ->check(CLI::PositiveNumber);
  route
      ->add_option("--min-depth", min_depth,
                   "a route cell needs construction when its MARS gap is at least this [m], e.g. one cube layer")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  route
      ->add_option("--min-natural", min_natural,
                   "natural ground shorter than this does not separate two sites [m] (default: --delta)")
      ->check(CLI::NonNegativeNumber);
  route
      ->add_option("--local-radius", local_radius,
                   "take each cell's MARS bound over the square of this half-side around it only, as a builder's local "
                   "map of its sensing range does [m]; 0: the whole terrain")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  route->add_flag("--json", route_json, "print JSON instead of text");

  if (const auto code = parse_command_line(app, argc, argv, "marsala-terrain", out, err)) return *code;

  try {
    if (*generate) {
      spec.params = parse_params(param_pairs);
      Heightmap map;
      try {
        map = terrain::generate_terrain(method, spec);
      } catch (const InvalidArgument& e) {
        throw UsageError(e.what());  // unknown method or parameter: the command line is wrong
      }
      terrain::write_asc(map, out_path);
      out << "generated " << method << " " << map.rows() << " x " << map.cols() << " at " << map.cell_size_m()
          << " m, heights " << map.min_height() << " .. " << map.max_height() << " m -> " << out_path << "\n";
    } else if (*import) {
      Heightmap map = import_terrain(load_terrain(in_path, fill_nodata), crop, target_cell_size, zero_base);
      // The written grid starts its own local frame at (0, 0).
      GridGeometry local = map.geometry();
      local.xll_m = 0.0;
      local.yll_m = 0.0;
      terrain::write_asc(Heightmap(local, map.heights()), out_path);
      out << "imported " << in_path << ": " << map.rows() << " x " << map.cols() << " at " << map.cell_size_m()
          << " m -> " << out_path << "\n";
    } else if (*info) {
      const Heightmap map = load_terrain(in_path, fill_nodata);
      const terrain::TerrainStats s = terrain::compute_terrain_stats(map);
      const auto& g = map.geometry();
      out << std::setprecision(6) << "file        " << in_path << "\n"
          << "size        " << s.rows << " rows x " << s.cols << " cols (" << map.size() << " cells)\n"
          << "cell size   " << s.cell_size_m << " m\n"
          << "extent      x " << g.xll_m << " .. " << g.xll_m + s.width_m << " m, y " << g.yll_m << " .. "
          << g.yll_m + s.height_m << " m (" << s.width_m << " x " << s.height_m << " m)\n"
          << "height      " << s.min_height_m << " .. " << s.max_height_m << " m (mean " << s.mean_height_m
          << " m, relief " << s.max_height_m - s.min_height_m << " m)\n"
          << "mean slope  " << s.mean_slope << " (rise over run; max " << s.max_slope << ")\n";
    } else if (*mars) {
      const Heightmap map = load_terrain(in_path, fill_nodata);
      const MarsProcessor processor(kappa);
      const Heightmap bound = processor.project(map);
      Heightmap gap(map.geometry(), (bound.heights() - map.heights()).eval());
      terrain::write_asc(write_gap ? gap : bound, out_path);
      out << "MARS at kappa " << kappa << ": gap volume " << deposition_target_volume(gap) << " m^3, largest gap "
          << gap.max_height() << " m -> " << out_path << "\n";
    } else if (*navigable) {
      const Heightmap map = load_terrain(in_path, fill_nodata);
      const NavigabilityProcessor processor(nav_params);
      const CellMask occupiable = processor.occupiable(map);
      if (write_occupiable) {
        terrain::write_asc(mask_as_heights(occupiable, map.geometry()), out_path);
        out << "occupiable " << count(occupiable) << " of " << map.size() << " cells ("
            << percent(count(occupiable), map.size()) << ") -> " << out_path << "\n";
      } else {
        if (origin_option->count() == 0) throw UsageError("navigable: --origin-cell ROW COL is required");
        check_origin(map, to_cell(origin));
        const CellMask reach = NavigabilityProcessor::navigable_from(occupiable, to_cell(origin));
        terrain::write_asc(mask_as_heights(reach, map.geometry()), out_path);
        out << "navigable from (" << origin.first << ", " << origin.second << "): " << count(reach) << " of "
            << map.size() << " cells (" << percent(count(reach), map.size()) << "); occupiable " << count(occupiable)
            << " -> " << out_path << "\n";
        if (count(reach) == 0) out << "note: the origin cell is not occupiable, so nothing is navigable\n";
      }
    } else if (*render) {
      const Heightmap map = load_terrain(in_path, fill_nodata);
      render::RenderOptions options;
      options.title = title;
      options.max_size_px = max_size_px;
      if (!render_origins.empty()) {
        const NavigabilityProcessor processor(render_params);
        const CellMask occupiable = processor.occupiable(map);
        CellMask reach = CellMask::Zero(map.rows(), map.cols());
        for (const auto& rc : render_origins) {
          const CellIndex origin_cell = to_cell(rc);
          check_origin(map, origin_cell);
          reach = reach.cwiseMax(NavigabilityProcessor::navigable_from(occupiable, origin_cell));
          options.markers.push_back(origin_cell);
        }
        options.navigable = reach;
      }
      if (render_gap) options.gap = MarsProcessor(render_params.kappa).gap(map);
      render::write_png(render::render_terrain(map, options), out_path);
      out << "rendered " << map.rows() << " x " << map.cols() << " -> " << out_path << "\n";
    } else if (*route) {
      std::vector<RouteQuery> queries;
      if (!pairs_path.empty()) {
        if (from_option->count() > 0 || to_option->count() > 0)
          throw UsageError("route: give either --pairs or --from and --to, not both");
        queries = read_route_pairs(pairs_path);
      } else {
        if (from_option->count() == 0 || to_option->count() == 0)
          throw UsageError("route: --from X Y and --to X Y (or --pairs FILE) are required");
        queries.push_back({{route_from.first, route_from.second}, {route_to.first, route_to.second}});
      }
      Heightmap map = import_terrain(load_terrain(in_path, fill_nodata), crop, target_cell_size, zero_base);
      std::vector<std::pair<CellIndex, CellIndex>> cells;
      for (std::size_t i = 0; i < queries.size(); ++i) {
        const std::string which = queries.size() > 1 ? fmt::format(" (route {})", i + 1) : std::string();
        cells.push_back(
            {cell_under(map, queries[i].from, "--from" + which), cell_under(map, queries[i].to, "--to" + which)});
      }
      RouteSiteParams site_params;
      const double site_kappa = build_kappa > 0.0 ? build_kappa : payload.kappa;
      site_params.width_m = band_width > 0.0 ? band_width : payload.delta_m;
      site_params.min_depth_m = min_depth;
      site_params.min_natural_m = min_natural >= 0.0 ? min_natural : payload.delta_m;
      const Heightmap gap = route_gap(map, site_kappa, local_radius);
      const Eigen::MatrixXi region = component_labels(NavigabilityProcessor(payload).occupiable(map));
      const auto& g = map.geometry();
      if (route_json)
        out << "{\"terrain\":{\"rows\":" << g.rows << ",\"cols\":" << g.cols
            << ",\"cell_size_m\":" << shortest(g.cell_size_m) << ",\"xll_m\":" << shortest(g.xll_m)
            << ",\"yll_m\":" << shortest(g.yll_m) << "},\"construction_kappa\":" << site_kappa
            << ",\"local_radius_m\":" << local_radius << ",\"width_m\":" << site_params.width_m
            << ",\"min_depth_m\":" << site_params.min_depth_m << ",\"min_natural_m\":" << site_params.min_natural_m
            << ",\"routes\":[";
      for (std::size_t i = 0; i < queries.size(); ++i) {
        const auto [from, to] = cells[i];
        const RouteSites r = plan_route_sites(gap, from, to, site_params);
        const Position a = map.cell_center(from), b = map.cell_center(to);
        const int from_region = region(from.row, from.col), to_region = region(to.row, to.col);
        const bool from_ok = from_region != 0, to_ok = to_region != 0;
        const bool connected = from_ok && from_region == to_region;
        if (route_json) {
          out << (i > 0 ? "," : "") << "{\"from\":[" << shortest(a.x) << "," << shortest(a.y) << "],\"to\":["
              << shortest(b.x) << "," << shortest(b.y) << "],\"length_m\":" << fixed(r.length_m, 3)
              << ",\"volume_m3\":" << fixed(r.band_volume_m3, 3) << ",\"band_cells\":" << r.band_cells
              << ",\"from_occupiable\":" << (from_ok ? "true" : "false")
              << ",\"to_occupiable\":" << (to_ok ? "true" : "false") << ",\"from_region\":" << from_region
              << ",\"to_region\":" << to_region << ",\"navigable_now\":" << (connected ? "true" : "false")
              << ",\"from_gap_m\":" << fixed(r.from_gap_m, 4) << ",\"to_gap_m\":" << fixed(r.to_gap_m, 4)
              << ",\"sites\":[";
          for (std::size_t k = 0; k < r.sites.size(); ++k)
            out << (k > 0 ? "," : "") << "{\"from_m\":" << fixed(r.sites[k].from_m, 3)
                << ",\"to_m\":" << fixed(r.sites[k].to_m, 3) << ",\"volume_m3\":" << fixed(r.sites[k].volume_m3, 3)
                << ",\"max_gap_m\":" << fixed(r.sites[k].max_gap_m, 3) << "}";
          out << "]}";
        } else {
          out << "route (" << shortest(a.x) << ", " << shortest(a.y) << ") -> (" << shortest(b.x) << ", "
              << shortest(b.y) << ") m: length " << fixed(r.length_m, 2) << " m, MARS gap "
              << fixed(r.band_volume_m3, 2) << " m^3 over a " << site_params.width_m << " m band (kappa " << site_kappa
              << (local_radius > 0.0 ? fmt::format(", bound within {} m", local_radius) : std::string()) << "), "
              << r.sites.size() << " construction site" << (r.sites.size() == 1 ? "" : "s") << "\n";
          for (std::size_t k = 0; k < r.sites.size(); ++k)
            out << "  site " << k + 1 << ": " << fixed(r.sites[k].from_m, 2) << " .. " << fixed(r.sites[k].to_m, 2)
                << " m along, " << fixed(r.sites[k].volume_m3, 2) << " m^3, deepest gap "
                << fixed(r.sites[k].max_gap_m, 2) << " m\n";
          out << "  payload: from " << (from_ok ? "occupiable" : "NOT occupiable") << " (gap " << fixed(r.from_gap_m, 3)
              << " m), to " << (to_ok ? "occupiable" : "NOT occupiable") << " (gap " << fixed(r.to_gap_m, 3) << " m), "
              << (connected ? "already navigable" : "not navigable") << " from one to the other\n";
        }
      }
      if (route_json) out << "]}\n";
    } else if (*render3d) {
      const Heightmap map = load_terrain(in_path, fill_nodata);
      double built_m3 = 0.0;
      if (!deposits_from.empty()) {
        const Heightmap before = load_terrain(deposits_from, fill_nodata);
        if (before.rows() != map.rows() || before.cols() != map.cols())
          throw UsageError("--deposits-from " + deposits_from + " is " + std::to_string(before.rows()) + " x " +
                           std::to_string(before.cols()) + " cells, " + in_path + " " + std::to_string(map.rows()) +
                           " x " + std::to_string(map.cols()));
        Heightmap deposit(map.geometry());
        for (int r = 0; r < map.rows(); ++r)
          for (int c = 0; c < map.cols(); ++c) {
            deposit(r, c) = std::max(0.0, map(r, c) - before(r, c));
            built_m3 += deposit(r, c) * map.cell_size_m() * map.cell_size_m();
          }
        view.deposit = std::move(deposit);
      }
      view.width_px = view_size.first;
      view.height_px = view_size.second;
      render::write_png(render::render_perspective(map, view), out_path);
      out << "rendered a perspective view of " << map.rows() << " x " << map.cols() << " cells";
      if (view.deposit) out << " (" << built_m3 << " m^3 built, tinted)";
      out << " -> " << out_path << "\n";
    }
  } catch (const UsageError& e) {
    err << "marsala-terrain: " << e.what() << " (run with --help for usage)\n";
    return kExitUsage;
  } catch (const Error& e) {
    err << "marsala-terrain: " << e.what() << "\n";
    return kExitData;
  } catch (const std::bad_alloc&) {
    err << "marsala-terrain: out of memory\n";
    return kExitData;
  }
  return 0;
}

}  // namespace marsala::cli
