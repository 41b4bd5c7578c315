// Runs the real marsala-terrain binary's compare subcommand on hand-made maps: its numbers (derived by hand below),
// its text and JSON, the body taken from a scenario, and bad input (exit 2, one line naming the file).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "unit/cli/terrain_cli_fixture.hpp"

namespace marsala {
namespace {

using test::CliRun;

std::string source_dir() {
  const char* dir = std::getenv("MARSALA_SOURCE_DIR");
  return dir ? dir : ".";
}

const char* const kHeader = "ncols 5\nnrows 4\nxllcorner 0\nyllcorner 0\ncellsize 0.5\nNODATA_value -9999\n";
// The truth: flat ground with a 1 m block at (1, 3).
const char* const kTrue = "0 0 0 0 0\n0 0 0 1 0\n0 0 0 0 0\n0 0 0 0 0\n";
// The robot's map: (0, 0) unknown, the block missed (read 0), (3, 4) read 0.1 m too high.
const char* const kBelieved = "-9999 0 0 0 0\n0 0 0 0 0\n0 0 0 0 0\n0 0 0 0 0.1\n";

class TerrainCompare : public test::TerrainCliFixture {
 protected:
  void SetUp() override {
    TerrainCliFixture::SetUp();
    write("true.asc", std::string(kHeader) + kTrue);
    write("believed.asc", std::string(kHeader) + kBelieved);
  }

  CliRun compare(const std::string& believed, const std::string& truth, const std::string& more = "") const {
    return run("compare '" + path(believed) + "' '" + path(truth) + "' " + more);
  }
};

TEST_F(TerrainCompare, CountsKnownCellsErrorsAndCellsBelievedPassableThatAreNot) {
  // Default body (ramp.pbtxt's builder): kappa 0.3, delta 1 m, eps 0.05 m: on 0.5 m cells the ball is the cell and its
  // 4 neighbours. Truth: the block and its 4 neighbours are not occupiable (1 m over 0.5 m), 15 of 20 cells are.
  // Believed: the unknown (0, 0) makes itself, (0, 1) and (1, 0) not passable; every other cell passes (0.1 m <= eps +
  // kappa 0.5 m = 0.2 m): 17, of which the 5 around the block are not occupiable in truth.
  // Errors over the 19 known cells: 17 x 0, 0.1, 1.0: median (rank 9) 0, p95 (rank floor(0.95 * 18 + 0.5) = 17) 0.1.
  const CliRun r = compare("believed.asc", "true.asc", "--json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["cells"], 20);
  EXPECT_EQ(j["known_cells"], 19);
  EXPECT_DOUBLE_EQ(j["known_fraction"].get<double>(), 0.95);
  EXPECT_EQ(j["median_error_m"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(j["p95_error_m"].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(j["max_error_m"].get<double>(), 1.0);
  EXPECT_EQ(j["believed_passable"], 17);
  EXPECT_EQ(j["believed_passable_not"], 5);
  EXPECT_EQ(j["true_passable"], 15);
  EXPECT_DOUBLE_EQ(j["body"]["kappa"].get<double>(), 0.3);

  const CliRun text = compare("believed.asc", "true.asc");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("known      19 of 20 cells (95.0 %)"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("median 0.0000 m, p95 0.1000 m, max 1.0000 m"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("17 cells believed passable"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("5 of them (29.4 %) are not on the true map (15 cells passable there)"), std::string::npos)
      << text.out;
}

TEST_F(TerrainCompare, TakesTheBodyFromTheCommandLineOrAScenario) {
  // A body of 0.8 m on 0.5 m cells: its ball is its own cell, every known cell is passable, every true cell too.
  for (const std::string& body :
       {std::string("--delta 0.8"),
        "--scenario '" + source_dir() + "/deploy/scenarios/hetero.pbtxt' --robot-type laser_scout"}) {
    const CliRun r = compare("believed.asc", "true.asc", body + " --json");
    ASSERT_EQ(r.exit_code, 0) << body << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_DOUBLE_EQ(j["body"]["delta_m"].get<double>(), 0.8) << body;
    EXPECT_EQ(j["believed_passable"], 19) << body;
    EXPECT_EQ(j["believed_passable_not"], 0) << body;
    EXPECT_EQ(j["true_passable"], 20) << body;
  }
  // A scenario with several types needs --robot-type; an unknown one is named with the valid ones.
  const std::string hetero = "--scenario '" + source_dir() + "/deploy/scenarios/hetero.pbtxt'";
  const CliRun several = compare("believed.asc", "true.asc", hetero);
  EXPECT_EQ(several.exit_code, 2);
  EXPECT_NE(several.err.find("give --robot-type"), std::string::npos) << several.err;
  const CliRun unknown = compare("believed.asc", "true.asc", hetero + " --robot-type nosuch");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("no robot type 'nosuch'; it has: husky"), std::string::npos) << unknown.err;
}

TEST_F(TerrainCompare, BadInputExitsTwoWithOneLineNamingTheFile) {
  write("small.asc", "ncols 4\nnrows 4\nxllcorner 0\nyllcorner 0\ncellsize 0.5\n0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 0\n");
  write("ragged.asc", std::string(kHeader) + "0 0 0 0 0\n0 0 0\n0 0 0 0 0\n0 0 0 0 0\n");
  write("nan.asc", std::string(kHeader) + "0 0 nan 0 0\n0 0 0 1 0\n0 0 0 0 0\n0 0 0 0 0\n");
  write("holes.asc", std::string(kHeader) + kBelieved);
  struct Case {
    std::string believed, truth, named;
  };
  for (const Case& c :
       {Case{"small.asc", "true.asc", "small.asc against"}, Case{"ragged.asc", "true.asc", "ragged.asc:8:"},
        Case{"nan.asc", "true.asc", "nan.asc:7:"}, Case{"believed.asc", "nan.asc", "nan.asc:7:"},
        Case{"believed.asc", "holes.asc", "holes.asc: cell (0, 0) is NODATA"},
        Case{"missing.asc", "true.asc", "missing.asc"}}) {
    const CliRun r = compare(c.believed, c.truth);
    EXPECT_EQ(r.exit_code, 2) << c.believed << " " << c.truth << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.named), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

}  // namespace
}  // namespace marsala
