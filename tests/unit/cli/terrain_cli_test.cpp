// Runs the real marsala-terrain binary: exit codes, messages, and the files it writes.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "marsala/terrain/asc_io.hpp"
#include "unit/cli/terrain_cli_fixture.hpp"

namespace marsala {
namespace {

using test::CliRun;
using test::slurp;

class TerrainCli : public test::TerrainCliFixture {};

TEST_F(TerrainCli, HelpOnEverySubcommand) {
  const CliRun top = run("--help");
  EXPECT_EQ(top.exit_code, 0);
  for (const char* sub : {"generate", "import", "info", "mars", "navigable", "render", "route", "compare"}) {
    EXPECT_NE(top.out.find(sub), std::string::npos) << sub;
    const CliRun r = run(std::string(sub) + " --help");
    EXPECT_EQ(r.exit_code, 0) << sub;
    EXPECT_NE(r.out.find("--"), std::string::npos) << sub << " help lists no options";
  }
  // generate's help lists the methods and their parameters.
  EXPECT_NE(run("generate --help").out.find("platform"), std::string::npos);
}

TEST_F(TerrainCli, UsageErrorsExitTwoWithOneLine) {
  for (const std::string& args :
       {std::string(""), std::string("frobnicate"), std::string("mars"), std::string("mars --kappa -1 x.asc -o y"),
        std::string("generate --method flat --rows 0 --cols 3 --cell-size 1 -o x.asc"),
        std::string("generate --method nosuch --rows 3 --cols 3 --cell-size 1 -o " + path("x.asc")),
        std::string("generate --method flat --rows 3 --cols 3 --cell-size 1 --param bogus=1 -o " + path("x.asc")),
        std::string("generate --method flat --rows 3 --cols 3 --cell-size 1 --param height=abc -o " + path("x.asc"))}) {
    const CliRun r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("marsala-terrain: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  // An unknown method lists the valid ones.
  const CliRun r = run("generate --method nosuch --rows 3 --cols 3 --cell-size 1 -o " + path("x.asc"));
  EXPECT_NE(r.err.find("fractal"), std::string::npos) << r.err;
}

TEST_F(TerrainCli, DataErrorsExitOneNamingFileAndLine) {
  write("bad.asc", "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 x\n");
  const CliRun r = run("info " + path("bad.asc"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad.asc:7"), std::string::npos) << r.err;

  write("nodata.asc", "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n1 -9999\n");
  const CliRun nodata = run("info " + path("nodata.asc"));
  EXPECT_EQ(nodata.exit_code, 1);
  EXPECT_NE(nodata.err.find("--fill-nodata"), std::string::npos) << nodata.err;
  EXPECT_EQ(run("info --fill-nodata " + path("nodata.asc")).exit_code, 0);
}

TEST_F(TerrainCli, GenerateThenInfo) {
  ASSERT_EQ(
      run("generate --method platform --seed 3 --rows 40 --cols 50 --cell-size 0.1 -o " + path("p.asc")).exit_code, 0);
  const Heightmap map = terrain::read_asc(path("p.asc"));
  EXPECT_EQ(map.rows(), 40);
  EXPECT_EQ(map.cols(), 50);
  EXPECT_DOUBLE_EQ(map.cell_size_m(), 0.1);
  EXPECT_DOUBLE_EQ(map.max_height(), 1.5);  // the paper's platform
  const CliRun info = run("info " + path("p.asc"));
  EXPECT_EQ(info.exit_code, 0);
  EXPECT_NE(info.out.find("40 rows x 50 cols"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("mean slope"), std::string::npos) << info.out;
  // Same seed, same file: determinism through the CLI.
  ASSERT_EQ(run("generate --method mix --seed 9 --rows 30 --cols 30 --cell-size 0.2 -o " + path("a.asc")).exit_code, 0);
  ASSERT_EQ(run("generate --method mix --seed 9 --rows 30 --cols 30 --cell-size 0.2 -o " + path("b.asc")).exit_code, 0);
  EXPECT_EQ(slurp(path("a.asc")), slurp(path("b.asc")));
}

TEST_F(TerrainCli, MarsGapOfASpikeIsACone) {
  // A 1 m spike in the middle of a flat 9 x 9 grid of 0.5 m cells; kappa 0.4.
  std::ostringstream asc;
  asc << "ncols 9\nnrows 9\nxllcorner 0\nyllcorner 0\ncellsize 0.5\n";
  for (int r = 0; r < 9; ++r) {
    for (int c = 0; c < 9; ++c) asc << (r == 4 && c == 4 ? "1" : "0") << (c < 8 ? " " : "\n");
  }
  write("spike.asc", asc.str());
  const CliRun r = run("mars --kappa 0.4 --gap " + path("spike.asc") + " -o " + path("gap.asc"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Heightmap gap = terrain::read_asc(path("gap.asc"));
  for (int row = 0; row < 9; ++row)
    for (int col = 0; col < 9; ++col) {
      const double expected =
          (row == 4 && col == 4) ? 0.0 : std::max(0.0, 1.0 - 0.4 * 0.5 * std::hypot(row - 4, col - 4));
      EXPECT_NEAR(gap(row, col), expected, 1e-12) << row << "," << col;
    }
  ASSERT_EQ(run("mars --kappa 0.4 " + path("spike.asc") + " -o " + path("p.asc")).exit_code, 0);
  EXPECT_NEAR(terrain::read_asc(path("p.asc"))(4, 6), 0.6, 1e-12);
}

// Terraces falling to the east (as tests/integration/scenarios/path_three_gaps.pbtxt): 40 x 240 cells of 0.25 m, in a
// frame whose lower-left corner is (100, 200) m, with 0.8 m cliffs at x = 115, 130 and 145 m. A kappa-0.2 ramp down
// each covers the 15 cells past the cliff (gaps 0.75 .. 0.05 m), so a route along y = 205.125 m from x = 105.125 m
// meets sites at 10 .. 13.5, 25 .. 28.5 and 40 .. 43.5 m, each 9 band rows (2 m) x 6 m x 0.0625 m^2 = 3.375 m^3.
std::string three_cliffs_asc() {
  std::ostringstream asc;
  asc << "ncols 240\nnrows 40\nxllcorner 100\nyllcorner 200\ncellsize 0.25\n";
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 240; ++c) {
      const double x = (c + 0.5) * 0.25;
      asc << 0.8 * ((x < 15.0) + (x < 30.0) + (x < 45.0)) << (c < 239 ? " " : "\n");
    }
  return asc.str();
}

TEST_F(TerrainCli, RouteFindsTheThreeRampsOfThreeCliffs) {
  write("cliffs.asc", three_cliffs_asc());
  const std::string args =
      "route " + path("cliffs.asc") + " --kappa 0.2 --delta 2 --eps 0.05 --from 105.125 205.125 --to 156.125 205.125";
  const CliRun text = run(args);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("m^3 over a 2 m band (kappa 0.2), 3 construction sites"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("site 2: 25.00 .. 28.50 m along, 3.3"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("length 51.00 m"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("not navigable"), std::string::npos) << text.out;
  const CliRun json = run(args + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  // Lengths, volumes and gaps keep the decimals of the text (3; gaps at the ends 4), as nlohmann::json writes them.
  EXPECT_NE(json.out.find("\"length_m\":51.0,\"volume_m3\":10.125"), std::string::npos) << json.out;
  EXPECT_NE(json.out.find("{\"from\":[105.125,205.125],\"to\":[156.125,205.125],"), std::string::npos) << json.out;
  // Each terrace is its own payload region (labelled in row-major order of its first cell: west to east).
  EXPECT_NE(json.out.find("\"from_region\":1,\"to_region\":4,\"navigable_now\":false"), std::string::npos) << json.out;
  for (const char* site : {"{\"from_m\":10.0,\"to_m\":13.5,\"volume_m3\":3.375,\"max_gap_m\":0.75}",
                           "{\"from_m\":25.0,\"to_m\":28.5,\"volume_m3\":3.375,\"max_gap_m\":0.75}",
                           "{\"from_m\":40.0,\"to_m\":43.5,\"volume_m3\":3.375,\"max_gap_m\":0.75}"})
    EXPECT_NE(json.out.find(site), std::string::npos) << site << "\n" << json.out;
  // Natural ground of 11.5 m between the ramps: asking for 12 m makes them one site; --pairs plans several routes.
  EXPECT_NE(run(args + " --min-natural 12").out.find("1 construction site\n  site 1: 10.00 .. 43.50 m along"),
            std::string::npos);
  write("pairs.txt", "# from, to\n105.125 205.125 156.125 205.125\n\n105.125 205.125 120.125 205.125  # one cliff\n");
  const CliRun pairs =
      run("route " + path("cliffs.asc") + " --kappa 0.2 --delta 2 --eps 0.05 --json --pairs " + path("pairs.txt"));
  ASSERT_EQ(pairs.exit_code, 0) << pairs.err;
  EXPECT_NE(pairs.out.find("\"length_m\":15.0,\"volume_m3\":3.375"), std::string::npos) << pairs.out;
  // One JSON document, as deploy/search_routes.py reads it: the routes in the order of the file.
  const nlohmann::json doc = nlohmann::json::parse(pairs.out);
  ASSERT_EQ(doc["routes"].size(), 2u);
  EXPECT_EQ(doc["routes"][0]["length_m"].get<double>(), 51.0);
  EXPECT_EQ(doc["routes"][1]["to"], nlohmann::json::parse("[120.125, 205.125]"));
  EXPECT_EQ(doc["routes"][1]["sites"].size(), 1u);
  EXPECT_EQ(doc["terrain"]["xll_m"].get<double>(), 100.0);
  // Cropped to the first two terraces (x 100 .. 130 m): one cliff left on the way to x = 125.125 m.
  const CliRun cropped = run("route " + path("cliffs.asc") +
                             " --crop 100 200 30 10 --kappa 0.2 --delta 2 --eps 0.05 --from 105.125 205.125 --to "
                             "125.125 205.125");
  EXPECT_NE(cropped.out.find("1 construction site"), std::string::npos) << cropped.out << cropped.err;
}

TEST_F(TerrainCli, RouteBadInputExitsTwoWithOneLine) {
  write("cliffs.asc", three_cliffs_asc());
  write("bad_pairs.txt", "105 205 156 abc\n");
  write("short_pairs.txt", "105 205 156\n");
  const std::string base = "route " + path("cliffs.asc") + " --kappa 0.2 --delta 2 --eps 0.05 ";
  for (const std::string& args :
       {base + "--from 105 205 --to 156 205 --frobnicate", base + "--from 105 205 --to 99 205",
        base + "--from 105 205 --to 156 300", base + "--from nan 205 --to 156 205", base + "--from 105 205",
        base + "--from 105 205 --to 156 205 --pairs " + path("bad_pairs.txt"),
        base + "--pairs " + path("bad_pairs.txt"), base + "--pairs " + path("short_pairs.txt"),
        base + "--from 105 205 --to 156 205 --width 0",
        "route " + path("cliffs.asc") + " --kappa 0.2 --from 105 205 --to 156 205"}) {
    const CliRun r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("marsala-terrain: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  EXPECT_NE(run(base + "--from 105 205 --to 99 205").err.find("off the terrain (x 100 .. 160 m"), std::string::npos);
  EXPECT_NE(run(base + "--pairs " + path("bad_pairs.txt")).err.find("bad_pairs.txt:1: 'abc'"), std::string::npos);
}

TEST_F(TerrainCli, NavigableAcrossAStep) {
  // 6 x 10 grid, cells 0.1 m; columns 5.. are 1 m higher. delta 0.2 m (ball radius 1 cell), eps 0.05.
  std::ostringstream asc;
  asc << "ncols 10\nnrows 6\nxllcorner 0\nyllcorner 0\ncellsize 0.1\n";
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 10; ++c) asc << (c >= 5 ? "1" : "0") << (c < 9 ? " " : "\n");
  write("step.asc", asc.str());
  const std::string nav = "navigable --kappa 0.3 --eps 0.05 --delta 0.2 " + path("step.asc");
  ASSERT_EQ(run(nav + " --origin-cell 2 0 -o " + path("n.asc")).exit_code, 0);
  const Heightmap n = terrain::read_asc(path("n.asc"));
  // Cells whose ball touches both sides (cols 4 and 5) are not occupiable: the low side (cols 0..3) is navigable.
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 10; ++c) EXPECT_EQ(n(r, c), c <= 3 ? 1.0 : 0.0) << r << "," << c;
  ASSERT_EQ(run(nav + " --occupiable -o " + path("o.asc")).exit_code, 0);
  const Heightmap o = terrain::read_asc(path("o.asc"));
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 10; ++c) EXPECT_EQ(o(r, c), (c == 4 || c == 5) ? 0.0 : 1.0) << r << "," << c;
  EXPECT_EQ(run(nav + " --origin-cell 6 0 -o " + path("n.asc")).exit_code, 1);
  EXPECT_EQ(run(nav + " -o " + path("n.asc")).exit_code, 2);  // no origin and no --occupiable
}

TEST_F(TerrainCli, RenderWritesAPng) {
  ASSERT_EQ(run("generate --method platform --rows 60 --cols 80 --cell-size 0.1 -o " + path("p.asc")).exit_code, 0);
  const CliRun r = run("render " + path("p.asc") + " -o " + path("p.png") +
                       " --navigable-from 2 2 --gap --kappa 0.5 --title platform");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string png = slurp(path("p.png"));
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  EXPECT_EQ(run("render " + path("p.asc") + " -o /nonexistent-dir/p.png").exit_code, 1);
}

TEST_F(TerrainCli, ImportCropsAndResamples) {
  ASSERT_EQ(run("generate --method ramp --rows 20 --cols 30 --cell-size 1 -o " + path("r.asc")).exit_code, 0);
  const CliRun r = run("import " + path("r.asc") + " --crop 5 5 10 8 --cell-size 0.5 -o " + path("c.asc"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Heightmap c = terrain::read_asc(path("c.asc"));
  EXPECT_EQ(c.cols(), 20);
  EXPECT_EQ(c.rows(), 16);
  EXPECT_DOUBLE_EQ(c.cell_size_m(), 0.5);
  EXPECT_DOUBLE_EQ(c.geometry().xll_m, 0.0);
}

TEST_F(TerrainCli, ImportsTheGaleGeoTiff) {
  const char* root = std::getenv("MARSALA_SOURCE_DIR");
  const std::string tif = std::string(root ? root : ".") + "/../shared/data/terrains/gale_crater_1m_original.tif";
  if (!std::ifstream(tif)) GTEST_SKIP() << "Gale crater DEM not found at " << tif << "; skipping";
  const CliRun r = run("import " + tif + " --crop 10 20 160 160 --cell-size 0.5 --zero-base -o " + path("g.asc"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Heightmap g = terrain::read_asc(path("g.asc"));
  EXPECT_EQ(g.rows(), 320);
  EXPECT_EQ(g.cols(), 320);
  EXPECT_DOUBLE_EQ(g.min_height(), 0.0);
  EXPECT_GT(g.max_height(), 5.0);  // a 160 m window of the crater has metres of relief
}

}  // namespace
}  // namespace marsala
