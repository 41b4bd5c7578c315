// marsala-agent --dump-map's folder: made when missing, refused when it is not one or holds another run's maps, and
// the map written whole (read back bit for bit, NODATA where unknown) with a record that counts what it holds.

#include "marsala/agent/runtime/map_dump.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::runtime {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir() {
  const fs::path dir = fs::path(::testing::TempDir()) /
                       ("map_dump_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::remove_all(dir);
  return dir;
}

/// A 3 x 4 terrain of distinct heights (some not short decimals), and a map that has been sent only tile (0, 1) of
/// it cut in 2 x 2 tiles: cells (0, 2), (0, 3), (1, 2), (1, 3).
Heightmap terrain() {
  Heightmap h({3, 4, 10.0, 20.0, 0.5}, 0.0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) h(r, c) = 0.1 * (r * 4 + c) + 1.0 / 3.0;
  return h;
}

MapDumpInfo info(const std::string& run_id, std::uint32_t id) {
  return {run_id, id, "husky-1", 42, "run_over", "laser"};
}

TEST(MapDump, MakesAMissingFolderAndRefusesWhatIsNoFolder) {
  const fs::path dir = fresh_dir() / "deeper" / "maps";
  const MapDump dump(dir.string());
  EXPECT_TRUE(fs::is_directory(dir));
  EXPECT_EQ(dump.height_path(7), (dir / "agent-7-height.asc").string());
  EXPECT_EQ(dump.record_path(7), (dir / "agent-7-map.json").string());
  std::ofstream(dir / "plain") << "x";
  EXPECT_THROW(MapDump((dir / "plain").string()), InvalidArgument);
  EXPECT_THROW(MapDump(""), InvalidArgument);
}

TEST(MapDump, WritesTheKnownCellsBitForBitAndNodataElsewhere) {
  const fs::path dir = fresh_dir();
  const MapDump dump(dir.string());
  const Heightmap h = terrain();
  executive::MappingSystem map(h.geometry(), 2);
  map.integrate_tile(test::cut_tile(h, 2, 0, 1));
  dump.write(map.known_map(), info("run-a", 1));

  terrain::AscReadOptions keep;
  keep.keep_nodata = true;
  const Heightmap back = terrain::read_asc(dump.height_path(1), keep);
  EXPECT_EQ(back.geometry().rows, 3);
  EXPECT_EQ(back.geometry().cols, 4);
  EXPECT_EQ(back.geometry().xll_m, 10.0);
  EXPECT_EQ(back.geometry().yll_m, 20.0);
  EXPECT_EQ(back.cell_size_m(), 0.5);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      const bool known = r <= 1 && c >= 2;
      if (known) {
        const double a = back(r, c), b = h(r, c);
        EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << r << ", " << c;
      } else {
        EXPECT_TRUE(std::isnan(back(r, c))) << r << ", " << c;
      }
    }
  const MapRecord record = read_map_record(dump.record_path(1));
  EXPECT_EQ(record.run_id, "run-a");
  EXPECT_EQ(record.agent_id, 1u);
  EXPECT_EQ(record.step, 42u);
  EXPECT_EQ(record.known_cells, 4);
  EXPECT_EQ(record.height_file, "agent-1-height.asc");
  // Nothing half: no temporary file is left beside them.
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) EXPECT_NE(e.path().extension(), ".tmp") << e.path();
}

TEST(MapDump, AFolderHoldsTheMapsOfOneRun) {
  const fs::path dir = fresh_dir();
  const Heightmap h = terrain();
  executive::MappingSystem map(h.geometry(), 2);
  map.integrate_tile(test::cut_tile(h, 2, 0, 0));
  {
    const MapDump dump(dir.string());
    EXPECT_EQ(dump.problem_for_run("run-a"), "");  // empty folder
    dump.write(map.known_map(), info("run-a", 1));
    dump.write(map.known_map(), info("run-a", 2));
  }
  const MapDump again(dir.string());              // a folder of readable records is fine at start-up
  EXPECT_EQ(again.problem_for_run("run-a"), "");  // the same run (a restarted agent) may write again
  const std::string problem = again.problem_for_run("run-b");
  EXPECT_NE(problem.find((dir / "agent-1-map.json").string()), std::string::npos) << problem;
  EXPECT_NE(problem.find("run 'run-a'"), std::string::npos) << problem;
  EXPECT_NE(problem.find("'run-b'"), std::string::npos) << problem;
  EXPECT_EQ(problem.find('\n'), std::string::npos);
  // A record that is not one is refused at start-up, naming it.
  std::ofstream(dir / "agent-3-map.json") << "{\"run_id\": \"run-a\"";
  try {
    const MapDump broken(dir.string());
    ADD_FAILURE() << "a malformed record was accepted";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("agent-3-map.json"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace marsala::agent::runtime
