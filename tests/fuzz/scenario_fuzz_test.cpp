// Fuzzes the scenario reader (common/scenario/scenario.hpp, protobuf text format) with seeded mutations of the
// repository's scenarios: every text loads or throws the project's error family naming the source; a loaded scenario
// keeps every promise of its validation (docs/runtime.md#scenario-validation); a small generated terrain it describes
// is built with the declared size and finite heights within the world's limits, or refused with a typed error.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <typeinfo>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/terrain/generators.hpp"

namespace marsala::scenario {
namespace {

constexpr const char* kSource = "fuzz/fuzz.pbtxt";
// Generated terrains up to this many cells are built too (larger ones would dominate the budget).
constexpr long long kMaxBuiltCells = 16384;

using Report = std::function<std::string()>;

bool sane(double v) { return std::isfinite(v) && std::abs(v) < kMaxMagnitude; }

void check_rectangle(double x0, double y0, double x1, double y1, const std::string& what, const Report& report) {
  ASSERT_TRUE(sane(x0) && sane(y0) && sane(x1) && sane(y1)) << what << "\n" << report();
  ASSERT_TRUE(x0 < x1 && y0 < y1) << what << "\n" << report();
}

void check_navigability(const NavigabilityParams& p, const std::string& what, const Report& report) {
  ASSERT_TRUE(sane(p.kappa) && p.kappa > 0.0) << what << ".kappa " << p.kappa << "\n" << report();
  ASSERT_TRUE(sane(p.delta_m) && p.delta_m > 0.0) << what << ".delta_m " << p.delta_m << "\n" << report();
  ASSERT_TRUE(sane(p.eps_m) && p.eps_m >= 0.0) << what << ".eps_m " << p.eps_m << "\n" << report();
}

/// The promises of load_scenario() (scenario.hpp, docs/runtime.md#scenario-validation) on an accepted scenario.
void check_loaded(const Scenario& s, const Report& report) {
  ASSERT_FALSE(s.name.empty()) << report();
  ASSERT_EQ(s.source_path, kSource) << report();
  ASSERT_NE(s.terrain.method.empty(), s.terrain.file.empty()) << "exactly one of generator and file\n" << report();
  if (!s.terrain.method.empty()) {
    ASSERT_GT(s.terrain.rows, 0) << report();
    ASSERT_GT(s.terrain.cols, 0) << report();
    ASSERT_TRUE(sane(s.terrain.cell_size_m) && s.terrain.cell_size_m > 0.0) << report();
    for (const auto& [key, value] : s.terrain.params) ASSERT_TRUE(sane(value)) << key << "\n" << report();
  } else {
    ASSERT_TRUE(sane(s.terrain.resample_cell_size_m) && s.terrain.resample_cell_size_m >= 0.0) << report();
    if (s.terrain.has_crop) {
      ASSERT_TRUE(sane(s.terrain.crop_x0_m) && sane(s.terrain.crop_y0_m) && sane(s.terrain.crop_width_m) &&
                  sane(s.terrain.crop_height_m) && s.terrain.crop_width_m > 0.0 && s.terrain.crop_height_m > 0.0)
          << report();
    }
  }
  ASSERT_FALSE(s.robot_types.empty()) << report();
  std::set<std::string> names;
  for (const RobotType& t : s.robot_types) {
    ASSERT_TRUE(names.insert(t.name).second) << "robot type '" << t.name << "' twice\n" << report();
    ASSERT_EQ(body_problem(t.body), "") << report();
    ASSERT_FALSE(t.behaviour.empty()) << report();
    ASSERT_FALSE(t.goal_synthesizer.empty()) << report();
    const NavigabilityParams build = construction_params(t);
    check_navigability(build, "construction", report);
    ASSERT_LE(build.kappa, t.body.navigability.kappa) << report();
  }
  ASSERT_FALSE(s.slots.empty()) << report();
  for (std::size_t i = 0; i < s.slots.size(); ++i) {
    const AgentSlot& slot = s.slots[i];
    ASSERT_EQ(slot.id, i + 1) << report();
    ASSERT_TRUE(names.count(slot.robot_type)) << report();
    ASSERT_EQ(s.robot_for(slot.id).name, slot.robot_type) << report();
    ASSERT_TRUE(sane(slot.start.x) && sane(slot.start.y) && sane(slot.target.x) && sane(slot.target.y))
        << report();
  }
  switch (s.completion) {
    case CompletionKind::kAgentsAtGoal:
      check_rectangle(s.goal.area.x0, s.goal.area.y0, s.goal.area.x1, s.goal.area.y1, "goal", report);
      break;
    case CompletionKind::kPayloadPath:
      check_navigability(s.payload_path.navigability, "payload_path", report);
      ASSERT_TRUE(sane(s.payload_path.from.x) && sane(s.payload_path.from.y) && sane(s.payload_path.to.x) &&
                  sane(s.payload_path.to.y))
          << report();
      ASSERT_GE(s.payload_path.check_every_steps, 1u) << report();
      break;
    case CompletionKind::kLevelSite:
      check_rectangle(s.site.area.x0, s.site.area.y0, s.site.area.x1, s.site.area.y1, "site", report);
      check_navigability(s.site.navigability, "site", report);
      ASSERT_TRUE(s.site.min_fraction > 0.0 && s.site.min_fraction <= 1.0) << report();
      ASSERT_GE(s.site.check_every_steps, 1u) << report();
      break;
  }
  if (s.has_goal_vector_map) {
    const GoalVectorMapSpec& m = s.goal_vector_map;
    check_rectangle(m.area.x0, m.area.y0, m.area.x1, m.area.y1, "goal_vector_map", report);
    ASSERT_TRUE(sane(m.strip_width_m) && m.strip_width_m > 0.0) << report();
    ASSERT_TRUE(sane(m.arrow_length_m) && m.arrow_length_m > 0.0) << report();
  }
  ASSERT_TRUE(sane(s.start_jitter_m) && s.start_jitter_m >= 0.0) << report();
  ASSERT_TRUE(sane(s.base.centre.x) && sane(s.base.centre.y) && sane(s.base.radius_m) && s.base.radius_m > 0.0) << report();
  ASSERT_GE(s.max_steps, 1u) << report();
  ASSERT_TRUE(sane(s.step_deadline_s) && s.step_deadline_s > 0.0) << report();
  ASSERT_TRUE(s.tile_size >= 1 && s.tile_size <= 4096) << report();
}

/// A small generated terrain: built as declared, heights finite within +-kMaxMagnitude; or a typed refusal.
void check_built_terrain(const Scenario& s, const Report& report) {
  std::optional<Heightmap> map;
  try {
    map = build_terrain(s);
  } catch (const Error& e) {
    ASSERT_NE(std::string(e.what()).find(kSource), std::string::npos)
        << "the message does not name the scenario: " << e.what() << "\n"
        << report();
    return;
  }
  ASSERT_EQ(map->rows(), s.terrain.rows) << report();
  ASSERT_EQ(map->cols(), s.terrain.cols) << report();
  ASSERT_EQ(map->cell_size_m(), s.terrain.cell_size_m) << report();
  for (long long i = 0; i < map->size(); ++i)
    ASSERT_TRUE(std::isfinite(map->data()[i]) && std::abs(map->data()[i]) <= kMaxMagnitude)
        << "cell " << i << " = " << map->data()[i] << "\n"
        << report();
}

/// Field names of idl/scenario.proto, and the punctuation and values of the text format.
std::vector<std::string> dictionary() {
  std::vector<std::string> words = {"{",
                                    "}",
                                    ":",
                                    "<",
                                    ">",
                                    "[",
                                    "]",
                                    ",",
                                    ";",
                                    "#",
                                    "\"",
                                    "'",
                                    "\"\\0\"",
                                    "\"\\377\"",
                                    "true",
                                    "false",
                                    "east",
                                    "north",
                                    "diagonal",
                                    "idle",
                                    "ramp_builder",
                                    "path_builder",
                                    "scripted",
                                    "fixed_target",
                                    "goal_vector_map",
                                    "key: \"height\" value: ",
                                    "params { key: \"\" value: 1 }",
                                    "-",
                                    "0x10",
                                    "\"/dev/zero\"",
                                    "1e309"};
  std::string deep;
  for (int i = 0; i < 120; ++i) deep += "terrain { ";
  words.push_back(deep);
  for (const std::string& name : terrain::generator_names()) words.push_back("\"" + name + "\"");
  const std::string proto = fuzz::read_file(fuzz::source_dir() + "/idl/scenario.proto");
  const std::regex field(R"(\b([a-z_0-9]+) = \d+;)");
  for (auto it = std::sregex_iterator(proto.begin(), proto.end(), field); it != std::sregex_iterator(); ++it)
    words.push_back((*it)[1].str());
  return words;
}

std::vector<std::string> seeds() {
  std::vector<std::string> out = {
      R"(name: "mini"
terrain { generator: "flat" rows: 20 cols: 30 cell_size_m: 0.5 }
robot_type { name: "bot" body { kappa: 0.3 delta_m: 1 max_step_m: 0.2 } construction { kappa: 0.2 } }
agent { robot_type: "bot" start { x_m: 1 y_m: 1 } target { x_m: 10 y_m: 5 } }
goal { x0_m: 9 y0_m: 4 x1_m: 11 y1_m: 6 min_height_m: 0.5 }
base { x_m: 1 y_m: 1 radius_m: 0.5 }
)",
      R"(name: "site"
terrain { generator: "gaussian_hills" rows: 16 cols: 16 cell_size_m: 0.25 seed: 7 params { key: "amplitude" value: 0.3 } }
robot_type { name: "a" behaviour: "idle" goal_synthesizer: "goal_vector_map" pipeline { separation_m: 1 } }
agent { robot_type: "a" start { x_m: 0.5 y_m: 0.5 } target { x_m: 3 y_m: 3 } }
agent { id: 2 robot_type: "a" start { x_m: 1.5 y_m: 0.5 } target { x_m: 3 y_m: 3 } }
site { x0_m: 1 y0_m: 1 x1_m: 3 y1_m: 3 min_fraction: 0.5 check_every_steps: 2 }
goal_vector_map { x0_m: 0 y0_m: 0 x1_m: 4 y1_m: 4 strip_width_m: 1 arrow_length_m: 0.5 heading: "north" }
start_jitter_m: 0.1 max_steps: 10 step_deadline_s: 1 tile_size: 8 seed: 3
)",
      R"(name: "payload"
terrain { generator: "platform" rows: 30 cols: 40 cell_size_m: 0.1 params { key: "height" value: 0.5 } }
robot_type { name: "b" }
agent { robot_type: "b" start { x_m: 0.5 y_m: 0.5 } target { x_m: 3 y_m: 2 } }
payload_path { body { kappa: 0.2 delta_m: 0.3 eps_m: 0.05 } from { x_m: 0.5 y_m: 0.5 } to { x_m: 3 y_m: 2 } }
)",
      R"(name: "file"
terrain { file: "t.asc" crop { x0_m: 0 y0_m: 0 width_m: 1 height_m: 1 } resample_cell_size_m: 0.5 zero_base: true }
robot_type { name: "c" }
agent { robot_type: "c" start { x_m: 0.5 y_m: 0.5 } target { x_m: 1 y_m: 1 } }
goal { x0_m: 0 y0_m: 0 x1_m: 1 y1_m: 1 }
)",
  };
  // The repository's scenarios, and whatever tiny files tests/fuzz/corpus/scenario holds.
  namespace fs = std::filesystem;
  const fs::path root(fuzz::source_dir());
  std::error_code ec;
  for (const char* dir : {"deploy/scenarios", "tests/integration/scenarios", "tests/fuzz/corpus/scenario"})
    for (const auto& entry : fs::directory_iterator(root / dir, ec)) out.push_back(fuzz::read_file(entry.path()));
  return out;
}

/// A corpus entry; the small generated scenarios (the first kSmallSeeds) a third of the time, so that terrains are
/// built often (the repository's scenarios are too large for the budget).
const std::string& pick_seed(const std::vector<std::string>& corpus, fuzz::Mutator& mutator) {
  constexpr std::size_t kSmallSeeds = 3;
  return mutator.chance(0.33) ? corpus[mutator.below(kSmallSeeds)] : mutator.pick(corpus);
}

TEST(ScenarioFuzz, EveryTextLoadsOrThrowsATypedErrorAndLoadedScenariosKeepTheirPromises) {
  const std::uint64_t seed = fuzz::seed(0x5CE4A210);
  const int iterations = fuzz::iterations(30000);
  fuzz::Mutator mutator(seed, dictionary());
  std::vector<std::string> corpus = seeds();
  ASSERT_GE(corpus.size(), 8u) << "the repository's scenarios were not found under " << fuzz::source_dir();
  const std::size_t fixed_seeds = corpus.size();
  const std::size_t kMaxCorpus = 128;
  fuzz::Watchdog watchdog;
  int loaded = 0, built = 0;
  for (int i = 0; i < iterations; ++i) {
    // The seeds themselves first (regressions in corpus/ replay as they are), then mutants.
    const std::string input =
        i < static_cast<int>(fixed_seeds) ? corpus[i] : mutator.mutate_text(pick_seed(corpus, mutator), corpus);
    const Report report = [&] { return fuzz::failure_report("scenario", seed, i, input, ".pbtxt"); };
    watchdog.arm(std::chrono::seconds(5), "scenario seed " + std::to_string(seed) + " iteration " + std::to_string(i),
                 input, fuzz::failure_path("scenario", seed, i, ".pbtxt"));
    const std::optional<Scenario> s = fuzz::load_or_refuse<Error>(
        [&] { return parse_scenario(input, kSource); },
        [&](const Error& e) {
          const std::string what = e.what();
          EXPECT_NE(what.find(kSource), std::string::npos) << "the message does not name the source: " << what << "\n"
                                                           << report();
          const bool typed = dynamic_cast<const ParseError*>(&e) || dynamic_cast<const InvalidArgument*>(&e);
          EXPECT_TRUE(typed) << "neither ParseError nor InvalidArgument: " << what << "\n" << report();
        },
        "marsala::Error", report);
    if (!::testing::Test::HasFailure() && s) {
      ++loaded;
      check_loaded(*s, report);
      // Only generated terrains: a fuzzed file name could name anything on this machine.
      if (!s->terrain.method.empty() && static_cast<long long>(s->terrain.rows) * s->terrain.cols <= kMaxBuiltCells) {
        ++built;
        try {
          check_built_terrain(*s, report);
        } catch (const std::exception& e) {
          ADD_FAILURE() << "building the terrain threw " << typeid(e).name() << ": " << e.what() << "\n" << report();
        }
      }
    }
    watchdog.disarm();
    if (::testing::Test::HasFailure()) return;
    if (s && input.size() < 8192) {
      if (corpus.size() < kMaxCorpus)
        corpus.push_back(input);
      else
        corpus[fixed_seeds + mutator.below(kMaxCorpus - fixed_seeds)] = input;
    }
  }
  EXPECT_GT(loaded, iterations / 50) << "only " << loaded << " of " << iterations << " scenarios loaded";
  EXPECT_GT(built, iterations / 200) << "only " << built << " terrains built";
  RecordProperty("loaded", loaded);
  RecordProperty("built", built);
}

}  // namespace
}  // namespace marsala::scenario
