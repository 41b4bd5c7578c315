// marsala-monitor replay: run logs written with RunLogWriter, replayed and compared with the same plan applied by
// hand; damaged, inconsistent and mismatched logs; frames; and the real binary's output and exit codes.
#include "marsala/monitor/replay.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/render/terrain_renderer.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/terrain/asc_io.hpp"

extern char** environ;

namespace marsala::monitor {
namespace {

namespace fs = std::filesystem;

constexpr int kRows = 6;
constexpr int kCols = 8;
constexpr double kCellSizeM = 0.5;
constexpr std::uint32_t kAgents = 3;

struct PlannedDeposition {
  int row;
  int col;
  double height_m;
};

struct PlannedRequest {
  std::uint32_t agent = 0;
  bool accepted = true;
  bool move = false;
  Position target;
  std::vector<PlannedDeposition> depositions;
};

/// What happens in one step: records before it (admissions, drops) and its requests.
struct PlannedStep {
  std::vector<std::uint32_t> admitted;
  std::vector<std::uint32_t> dropped;
  std::vector<PlannedRequest> requests;
};

Heightmap initial_terrain() {
  Heightmap t(GridGeometry{kRows, kCols, 10.0, 20.0, kCellSizeM});
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) t(r, c) = 0.1 * r - 0.03 * c + 0.001 * r * c;
  return t;
}

/// Twelve steps of three agents: agent 3 dropped before step 5 and back before step 8; every step has accepted
/// depositions (one cell raised twice in a step by two agents), a rejected request that would raise a cell, and moves.
std::vector<PlannedStep> plan() {
  std::vector<PlannedStep> steps(12);
  steps[0].admitted = {1, 2, 3};
  steps[5].dropped = {3};
  steps[8].admitted = {3};
  for (int k = 0; k < 12; ++k) {
    PlannedStep& s = steps[k];
    const double h = 0.05 * (1 + k % 3);
    s.requests.push_back({1, true, true, {10.25 + 0.2 * k, 21.0}, {{k % kRows, 1, h}, {(k + 2) % kRows, 2, 0.05}}});
    s.requests.push_back({2, k % 4 != 1, k % 2 == 0, {12.0, 21.0 + 0.1 * k}, {{2, (k + 3) % kCols, 0.1}}});
    if (k < 5 || k >= 8) s.requests.push_back({3, true, false, {}, {{k % kRows, 1, 0.05}}});
    if (k % 3 == 0) s.requests.push_back({2, false, true, {50.0, 50.0}, {{0, 0, 0.5}}});  // a duplicate, rejected
  }
  return steps;
}

/// The plan applied by hand: the terrain after `steps` steps.
Heightmap apply_by_hand(const std::vector<PlannedStep>& steps, std::size_t count) {
  Heightmap t = initial_terrain();
  for (std::size_t k = 0; k < count; ++k)
    for (const PlannedRequest& q : steps[k].requests)
      if (q.accepted)
        for (const PlannedDeposition& d : q.depositions) t(d.row, d.col) += d.height_m;
  return t;
}

/// How a test log deviates from the plan.
struct Tamper {
  std::function<void(std::uint64_t&)> step_number;  ///< renumber step k
  double volume_error_m3 = 0.0;                     ///< added to every logged volume from step 6 on
  std::string end_sha;                              ///< the RunEnd's sha instead of the true one
  bool end = true;                                  ///< write a RunEnd
};

class ReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("marsala_replay_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string dir() const { return dir_.string(); }
  std::string log_path() const { return (dir_ / "run.log").string(); }

  /// Writes terrain_initial.asc and run.log for the plan; returns the byte offset after each step record.
  std::vector<std::uint64_t> write_run(const Tamper& tamper = {}) {
    const Heightmap initial = initial_terrain();
    terrain::write_asc(initial, (dir_ / "terrain_initial.asc").string());
    proto::LogHeader header;
    header.set_scenario("replay_test");
    header.set_run_id("replay_test-d9");
    header.set_agents(kAgents);
    header.set_max_steps(100);
    header.set_rows(kRows);
    header.set_cols(kCols);
    header.set_cell_size_m(kCellSizeM);
    header.set_initial_terrain_sha256(runlog::terrain_sha256(initial));
    runlog::RunLogWriter writer = runlog::RunLogWriter::create(log_path(), header);
    std::vector<std::uint64_t> step_ends;
    double volume_m3 = 0.0;
    const std::vector<PlannedStep> steps = plan();
    for (std::size_t k = 0; k < steps.size(); ++k) {
      for (std::uint32_t id : steps[k].admitted) {
        proto::LogRecord r;
        r.mutable_admitted()->set_step(k);
        r.mutable_admitted()->set_agent_id(id);
        r.mutable_admitted()->set_name("builder-" + std::to_string(id));
        r.mutable_admitted()->set_readmission(k > 0);
        writer.append(r);
      }
      for (std::uint32_t id : steps[k].dropped) {
        proto::LogRecord r;
        r.mutable_dropped()->set_step(k);
        r.mutable_dropped()->set_agent_id(id);
        r.mutable_dropped()->set_reason("request writer lost liveliness");
        writer.append(r);
      }
      proto::LogRecord r;
      proto::StepRecord& s = *r.mutable_step();
      std::uint64_t number = k;
      if (tamper.step_number) tamper.step_number(number);
      s.set_step(number);
      for (const PlannedRequest& q : steps[k].requests) {
        proto::LoggedRequest& l = *s.add_requests();
        l.set_channel_id(q.agent);
        l.set_agent_id(q.agent);
        l.set_step(k);
        l.set_move(q.move);
        l.set_target_x_m(q.target.x);
        l.set_target_y_m(q.target.y);
        l.set_accepted(q.accepted);
        double request_m3 = 0.0;
        for (const PlannedDeposition& d : q.depositions) {
          proto::LoggedDeposition& ld = *l.add_depositions();
          ld.set_row(d.row);
          ld.set_col(d.col);
          ld.set_height_m(d.height_m);
          request_m3 += d.height_m * kCellSizeM * kCellSizeM;
        }
        if (q.accepted) volume_m3 += request_m3;
      }
      s.set_deposited_volume_m3(volume_m3 + (k >= 6 ? tamper.volume_error_m3 : 0.0));
      writer.append(r);
      step_ends.push_back(writer.bytes());
    }
    if (tamper.end) {
      proto::LogRecord r;
      r.mutable_end()->set_steps(steps.size());
      r.mutable_end()->set_end_reason("completed");
      r.mutable_end()->set_terrain_sha256(tamper.end_sha.empty() ? runlog::terrain_sha256(apply_by_hand(steps, 12))
                                                                 : tamper.end_sha);
      writer.append(r);
    }
    return step_ends;
  }

  fs::path dir_;
};

void expect_same_terrain(const Heightmap& got, const Heightmap& expected) {
  ASSERT_EQ(got.rows(), expected.rows());
  ASSERT_EQ(got.cols(), expected.cols());
  for (int r = 0; r < got.rows(); ++r)
    for (int c = 0; c < got.cols(); ++c) EXPECT_EQ(got(r, c), expected(r, c)) << "cell " << r << ", " << c;
}

/// The message of the Error replay_run throws, or "" when it does not throw.
std::string replay_error(const std::string& dir, const ReplayOptions& options = {}) {
  try {
    replay_run(dir, options);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST_F(ReplayTest, RebuildsTheTerrainTheLogDescribes) {
  write_run();
  const ReplayReport r = replay_run(dir(), {});
  expect_same_terrain(r.terrain, apply_by_hand(plan(), 12));
  EXPECT_EQ(r.terrain_sha256, runlog::terrain_sha256(apply_by_hand(plan(), 12)));
  EXPECT_EQ(r.steps, 12u);
  EXPECT_EQ(r.slots, kAgents);
  EXPECT_EQ(r.admitted, 3u);
  EXPECT_EQ(r.dropped, 0u);  // agent 3 came back
  ASSERT_TRUE(r.end_reason);
  EXPECT_EQ(*r.end_reason, "completed");
  EXPECT_TRUE(r.tail_problem.empty());
  std::uint64_t requests = 0, accepted = 0;
  double volume_m3 = 0.0;
  for (const PlannedStep& s : plan())
    for (const PlannedRequest& q : s.requests) {
      ++requests;
      if (!q.accepted) continue;
      ++accepted;
      for (const PlannedDeposition& d : q.depositions) volume_m3 += d.height_m * kCellSizeM * kCellSizeM;
    }
  EXPECT_EQ(r.requests, requests);
  EXPECT_EQ(r.accepted, accepted);
  EXPECT_NEAR(r.deposited_volume_m3, volume_m3, 1e-12);
  const std::string text = format_replay_report(r);
  EXPECT_EQ(text.substr(text.rfind('\n', text.size() - 2) + 1), "terrain_sha256 " + r.terrain_sha256 + "\n");
}

TEST(TerrainReplayer, KeepsDepositorsAndPositionsOfAcceptedRequestsOnly) {
  proto::LogHeader header;
  header.set_agents(2);
  header.set_rows(2);
  header.set_cols(2);
  header.set_cell_size_m(1.0);
  TerrainReplayer replayer(header, Heightmap(GridGeometry{2, 2, 0.0, 0.0, 1.0}), "run.log");
  proto::LogRecord r;
  proto::StepRecord& s = *r.mutable_step();
  for (std::uint32_t id : {1u, 2u}) {
    proto::LoggedRequest& q = *s.add_requests();
    q.set_agent_id(id);
    q.set_channel_id(id);
    q.set_move(true);
    q.set_target_x_m(id);
    q.set_target_y_m(0.5);
    q.set_accepted(id == 1);
    proto::LoggedDeposition& d = *q.add_depositions();
    d.set_row(0);
    d.set_col(1);
    d.set_height_m(0.25);
  }
  s.set_deposited_volume_m3(0.25);
  replayer.apply(r, 100);
  EXPECT_EQ(replayer.steps(), 1u);
  EXPECT_EQ(replayer.terrain()(0, 1), 0.25);
  EXPECT_EQ(replayer.depositor()(0, 1), 1u);
  EXPECT_EQ(replayer.depositor()(0, 0), 0u);
  ASSERT_TRUE(replayer.agents().at(1).position);
  EXPECT_EQ(replayer.agents().at(1).position->x, 1.0);
  EXPECT_FALSE(replayer.agents().at(2).position);
  EXPECT_EQ(replayer.agents().at(2).rejected, 1u);
  // A deposition the world accepted off the grid is a broken log.
  r.mutable_step()->set_step(1);
  r.mutable_step()->mutable_requests(0)->mutable_depositions(0)->set_row(2);
  r.mutable_step()->set_deposited_volume_m3(0.5);
  EXPECT_THROW(replayer.apply(r, 200), ParseError);
}

TEST(TerrainReplayer, GivesAStartedSlotItsHeadingAndMaterialAsTheWorldApplies) {
  // docs/runtime.md#heading and #applying-requests: admitted at its start facing its target, full; a motion of
  // non-zero length turns it, one to where it stands does not; a deposition takes its volume off, a refill fills it.
  proto::LogHeader header;
  header.set_agents(1);
  header.set_rows(2);
  header.set_cols(2);
  header.set_cell_size_m(1.0);
  TerrainReplayer replayer(header, Heightmap(GridGeometry{2, 2, 0.0, 0.0, 1.0}), "run.log");
  replayer.set_start(1, SlotStart{Position{0.5, 0.5}, Position{0.5, 1.5}, 2.0});
  proto::LogRecord admitted;
  admitted.mutable_admitted()->set_agent_id(1);
  replayer.apply(admitted, 10);
  const ReplayedAgent& a = replayer.agents().at(1);
  ASSERT_TRUE(a.position);
  EXPECT_EQ(a.position->x, 0.5);
  EXPECT_DOUBLE_EQ(a.heading_rad, std::acos(0.0));  // north, towards its target
  EXPECT_EQ(a.material_m3, 2.0);
  double volume = 0.0;
  const auto step = [&](std::uint64_t k, double x, double y, double height_m, bool refill) {
    proto::LogRecord r;
    r.mutable_step()->set_step(k);
    proto::LoggedRequest& q = *r.mutable_step()->add_requests();
    q.set_agent_id(1);
    q.set_channel_id(1);
    q.set_accepted(true);
    q.set_move(true);
    q.set_target_x_m(x);
    q.set_target_y_m(y);
    q.set_refill(refill);
    if (height_m > 0.0) {
      proto::LoggedDeposition& d = *q.add_depositions();
      d.set_row(0);
      d.set_col(0);
      d.set_height_m(height_m);
    }
    volume += height_m;
    r.mutable_step()->set_deposited_volume_m3(volume);
    replayer.apply(r, 20 + k);
  };
  step(0, 1.5, 0.5, 0.5, false);  // east, 0.5 m^3 off
  EXPECT_DOUBLE_EQ(a.heading_rad, 0.0);
  EXPECT_DOUBLE_EQ(a.material_m3, 1.5);
  step(1, 1.5, 0.5, 2.0, false);  // standing still: the heading stays; never below 0
  EXPECT_DOUBLE_EQ(a.heading_rad, 0.0);
  EXPECT_EQ(a.material_m3, 0.0);
  step(2, 0.5, 0.5, 0.0, true);  // west, full again
  EXPECT_DOUBLE_EQ(a.heading_rad, std::atan2(0.0, -1.0));
  EXPECT_EQ(a.material_m3, 2.0);
}

TEST(TerrainReplayer, WithoutAStartHeadingAndMaterialStayUnknown) {
  proto::LogHeader header;
  header.set_agents(1);
  TerrainReplayer replayer(header, Heightmap(GridGeometry{2, 2, 0.0, 0.0, 1.0}), "run.log");
  proto::LogRecord admitted;
  admitted.mutable_admitted()->set_agent_id(1);
  replayer.apply(admitted, 10);
  EXPECT_TRUE(std::isnan(replayer.agents().at(1).heading_rad));
  EXPECT_TRUE(std::isnan(replayer.agents().at(1).material_m3));
  EXPECT_FALSE(replayer.agents().at(1).position);
}

TEST_F(ReplayTest, ToStepGivesTheTerrainTheWorldAwaitedThatStepOn) {
  write_run();
  for (std::uint64_t n : {0u, 1u, 5u, 11u, 12u}) {
    ReplayOptions o;
    o.to_step = n;
    const ReplayReport r = replay_run(dir(), o);
    EXPECT_EQ(r.steps, n);
    expect_same_terrain(r.terrain, apply_by_hand(plan(), n));
    EXPECT_EQ(r.end_reason.has_value(), n == 12) << n;  // the run's end is checked only when reached
  }
  ReplayOptions beyond;
  beyond.to_step = 13;
  const std::string e = replay_error(dir(), beyond);
  EXPECT_NE(e.find("holds 12 steps"), std::string::npos) << e;
  EXPECT_NE(e.find("--to-step 13"), std::string::npos) << e;
}

TEST_F(ReplayTest, ATruncatedTailReplaysTheWholeStepsBeforeTheCut) {
  const std::vector<std::uint64_t> ends = write_run({});
  const std::string full = (dir_ / "full.log").string();
  fs::copy_file(log_path(), full);
  // Cuts: inside the frame of step 0, inside several records' payloads, exactly at a boundary, inside the RunEnd.
  for (std::uint64_t cut : {ends[0] - 30, ends[0] + 3, ends[3] - 1, ends[3], ends[3] + 9, ends[10] + 5, ends[11] + 1,
                            fs::file_size(full) - 1}) {
    fs::copy_file(full, log_path(), fs::copy_options::overwrite_existing);
    fs::resize_file(log_path(), cut);
    std::size_t whole = 0;
    while (whole < ends.size() && ends[whole] <= cut) ++whole;
    const ReplayReport r = replay_run(dir(), {});
    EXPECT_EQ(r.steps, whole) << "cut at " << cut;
    expect_same_terrain(r.terrain, apply_by_hand(plan(), whole));
    EXPECT_FALSE(r.end_reason);
    const bool at_boundary = cut == ends[3];
    EXPECT_EQ(r.tail_problem.empty(), at_boundary) << "cut at " << cut << ": " << r.tail_problem;
    if (!at_boundary) {
      EXPECT_NE(r.tail_problem.find("truncated record"), std::string::npos) << r.tail_problem;
    }
  }
}

TEST_F(ReplayTest, AFlippedByteEndsTheReplayAtTheRecordBeforeIt) {
  const std::vector<std::uint64_t> ends = write_run();
  std::fstream f(log_path(), std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(static_cast<std::streamoff>(ends[6] + 20));  // inside step 7's payload
  const char byte = static_cast<char>(f.get());
  f.seekp(static_cast<std::streamoff>(ends[6] + 20));
  f.put(static_cast<char>(byte ^ 0x10));
  f.close();
  const ReplayReport r = replay_run(dir(), {});
  EXPECT_EQ(r.steps, 7u);
  expect_same_terrain(r.terrain, apply_by_hand(plan(), 7));
  EXPECT_NE(r.tail_problem.find("checksum mismatch"), std::string::npos) << r.tail_problem;
  EXPECT_NE(r.tail_problem.find("at byte " + std::to_string(ends[6])), std::string::npos) << r.tail_problem;
}

TEST_F(ReplayTest, AStepGapOrRepeatIsAnErrorNamingTheByte) {
  Tamper gap;
  gap.step_number = [](std::uint64_t& k) { k += k >= 4 ? 1 : 0; };
  const std::vector<std::uint64_t> ends = write_run(gap);
  std::string e = replay_error(dir());
  EXPECT_NE(e.find("run.log"), std::string::npos) << e;
  EXPECT_NE(e.find("step record at byte "), std::string::npos) << e;
  EXPECT_NE(e.find("step 5 where step 4 was due (a gap)"), std::string::npos) << e;

  fs::remove(log_path());
  Tamper repeat;
  repeat.step_number = [](std::uint64_t& k) { k -= k == 4 ? 1 : 0; };
  write_run(repeat);
  e = replay_error(dir());
  EXPECT_NE(e.find("step 3 where step 4 was due (a repeat)"), std::string::npos) << e;
}

TEST_F(ReplayTest, ARunEndShaMismatchIsAnError) {
  Tamper wrong;
  wrong.end_sha = std::string(64, 'a');
  write_run(wrong);
  const std::string e = replay_error(dir());
  EXPECT_NE(e.find("run end record at byte"), std::string::npos) << e;
  EXPECT_NE(e.find("differs from the replayed terrain's " + runlog::terrain_sha256(apply_by_hand(plan(), 12))),
            std::string::npos)
      << e;
}

TEST_F(ReplayTest, AVolumeMismatchIsAnError) {
  Tamper off;
  off.volume_error_m3 = 1e-6;
  write_run(off);
  const std::string e = replay_error(dir());
  EXPECT_NE(e.find("step 6: the log says"), std::string::npos) << e;
  EXPECT_NE(e.find("disagree"), std::string::npos) << e;

  // Within the tolerance (1e-9 relative) it is the same volume.
  fs::remove(log_path());
  Tamper tiny;
  tiny.volume_error_m3 = 1e-15;
  write_run(tiny);
  EXPECT_EQ(replay_error(dir()), "");
}

TEST_F(ReplayTest, AnotherInitialTerrainIsAnErrorNamingTheFile) {
  write_run();
  const std::string asc = (dir_ / "terrain_initial.asc").string();
  Heightmap changed = initial_terrain();
  changed(2, 3) += 1e-12;
  terrain::write_asc(changed, asc);
  std::string e = replay_error(dir());
  EXPECT_EQ(e.rfind(asc + ": SHA-256 ", 0), 0u) << e;
  EXPECT_NE(e.find("not this run's initial terrain"), std::string::npos) << e;

  terrain::write_asc(Heightmap(GridGeometry{kRows, kCols + 1, 10.0, 20.0, kCellSizeM}), asc);
  e = replay_error(dir());
  EXPECT_NE(e.find(asc + ": 6 x 9 cells of 0.5 m, but the run log's header says 6 x 8 cells"), std::string::npos) << e;

  fs::remove(asc);
  EXPECT_NE(replay_error(dir()).find("terrain_initial.asc"), std::string::npos);
}

/// Width and height from a PNG's signature and IHDR chunk, or {0, 0} when it is not a PNG.
std::pair<int, int> png_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[24] = {};
  if (!in.read(reinterpret_cast<char*>(head), sizeof head)) return {0, 0};
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (std::memcmp(head, signature, 8) != 0 || std::memcmp(head + 12, "IHDR", 4) != 0) return {0, 0};
  auto be32 = [&](int at) { return (head[at] << 24) | (head[at + 1] << 16) | (head[at + 2] << 8) | head[at + 3]; };
  return {be32(16), be32(20)};
}

/// The frame the replay should draw after `steps` steps, rendered here from a replayer fed the same log.
render::Image expected_frame(const std::string& dir, std::uint64_t steps) {
  runlog::RunLogReader reader(dir + "/run.log");
  TerrainReplayer replayer(reader.header(), terrain::read_asc(dir + "/terrain_initial.asc"), "run.log");
  proto::LogRecord record;
  while (reader.next(record) && !(record.has_step() && replayer.steps() == steps)) replayer.apply(record, 0);
  return render::render_terrain(replayer.terrain(), replay_picture_options(replayer));
}

TEST_F(ReplayTest, FramesEveryKStepsAndTheLast) {
  write_run();
  ReplayOptions o;
  o.frames_every = 5;
  const ReplayReport r = replay_run(dir(), o);
  EXPECT_EQ(r.frames_dir, (dir_ / "replay").string());
  EXPECT_EQ(r.frames, 4u);
  EXPECT_EQ(r.timelapse, "");
  EXPECT_EQ(r.timelapse_note, "skipped timelapse.mp4: ffmpeg is not installed (not on PATH)");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(r.frames_dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names,
            (std::vector<std::string>{"frame_000000.png", "frame_000005.png", "frame_000010.png", "frame_000012.png"}));
  for (std::uint64_t step : {0u, 5u, 10u, 12u}) {
    const render::Image expected = expected_frame(dir(), step);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06u.png", static_cast<unsigned>(step));
    EXPECT_EQ(png_size((fs::path(r.frames_dir) / name).string()), std::make_pair(expected.width, expected.height))
        << name;
  }
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_NE(e.path().extension(), ".tmp") << e.path();
  EXPECT_NE(format_replay_report(r).find("frames: 4 in " + r.frames_dir), std::string::npos);
}

TEST_F(ReplayTest, PictureOptionsTintDepositorsAndDrawAgents) {
  write_run();
  runlog::RunLogReader reader(log_path());
  TerrainReplayer replayer(reader.header(), initial_terrain(), "run.log");
  proto::LogRecord record;
  while (reader.next(record)) replayer.apply(record, 0);
  const render::RenderOptions o = replay_picture_options(replayer);
  ASSERT_TRUE(o.labels);
  EXPECT_EQ((*o.labels)(2, 1), replayer.depositor()(2, 1));
  EXPECT_EQ(o.title, "replay_test: step 12");
  ASSERT_EQ(o.points.size(), 2u);  // agents 1 and 2 moved; agent 3 never did
  EXPECT_EQ(o.points[0].colour, render::label_colour(1));
  EXPECT_EQ(o.points[0].at.x, 10.25 + 0.2 * 11);
  ASSERT_EQ(o.legend_entries.size(), 3u);
  EXPECT_EQ(o.legend_entries[2].text, "agent 3");
}

TEST_F(ReplayTest, AFramesFolderHoldingFramesIsRefused) {
  write_run();
  ReplayOptions o;
  o.frames_every = 4;
  o.frames_dir = (dir_ / "frames").string();
  fs::create_directories(o.frames_dir);  // empty: fine
  replay_run(dir(), o);
  const std::string e = replay_error(dir(), o);
  EXPECT_NE(e.find("frames folder '" + o.frames_dir + "' already holds a replay (4 files, e.g. frame_000000.png)"),
            std::string::npos)
      << e;
  EXPECT_TRUE(fs::exists(fs::path(o.frames_dir) / "frame_000012.png"));
}

TEST_F(ReplayTest, WithFfmpegOnThePathTheFramesBecomeATimelapse) {
  write_run();
  // A stand-in ffmpeg that records its arguments and writes its last one, the output file.
  const fs::path bin = dir_ / "bin";
  fs::create_directories(bin);
  {
    std::ofstream script(bin / "ffmpeg");
    script << "#!/bin/sh\necho \"$@\" > '" << (dir_ / "ffmpeg_args").string() << "'\nls \"$(dirname \"$7\")\" > '"
           << (dir_ / "ffmpeg_inputs").string() << "'\nfor a; do last=$a; done\necho video > \"$last\"\n";
  }
  fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
  ReplayOptions o;
  o.frames_every = 6;
  o.search_path = "/nonexistent:" + bin.string();
  const ReplayReport r = replay_run(dir(), o);
  EXPECT_EQ(r.timelapse, (dir_ / "replay" / "timelapse.mp4").string());
  EXPECT_TRUE(fs::exists(r.timelapse));
  EXPECT_FALSE(fs::exists(dir_ / "replay" / ".timelapse_frames"));
  EXPECT_FALSE(fs::exists(r.timelapse + ".tmp"));
  std::ifstream args(dir_ / "ffmpeg_args"), inputs(dir_ / "ffmpeg_inputs");
  std::stringstream a, i;
  a << args.rdbuf();
  i << inputs.rdbuf();
  EXPECT_NE(a.str().find("-framerate 10 -i " + (dir_ / "replay" / ".timelapse_frames" / "%06d.png").string()),
            std::string::npos)
      << a.str();
  EXPECT_NE(a.str().find("-pix_fmt yuv420p -vf pad="), std::string::npos) << a.str();
  EXPECT_EQ(i.str(), "000000.png\n000001.png\n000002.png\n");  // steps 0, 6, 12
}

// The real binary: the summary's last line, the tail warning and the exit codes.
struct BinaryRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

BinaryRun run_monitor(const std::vector<std::string>& args, const fs::path& scratch) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string out_path = (scratch / "stdout").string(), err_path = (scratch / "stderr").string();
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> all = {MARSALA_MONITOR_BIN};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  BinaryRun run;
  EXPECT_EQ(posix_spawn(&pid, MARSALA_MONITOR_BIN, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  EXPECT_EQ(waitpid(pid, &status, 0), pid);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream out(out_path), err(err_path);
  std::stringstream o, e;
  o << out.rdbuf();
  e << err.rdbuf();
  run.out = o.str();
  run.err = e.str();
  return run;
}

TEST_F(ReplayTest, TheBinaryPrintsTheShaLastAndExitsByOutcome) {
  const std::vector<std::uint64_t> ends = write_run();
  const fs::path scratch = dir_ / "scratch";
  fs::create_directories(scratch);
  const std::string sha = runlog::terrain_sha256(apply_by_hand(plan(), 12));

  BinaryRun r = run_monitor({"replay", dir()}, scratch);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  ASSERT_GE(r.out.size(), 80u);
  EXPECT_EQ(r.out.substr(r.out.size() - 80), "terrain_sha256 " + sha + "\n");
  EXPECT_NE(r.out.find("steps 12, agents 3 admitted of 3 slots"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("steps/s"), std::string::npos) << r.out;

  r = run_monitor({"replay", dir(), "--to-step", "5"}, scratch);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.substr(r.out.size() - 80),
            "terrain_sha256 " + runlog::terrain_sha256(apply_by_hand(plan(), 5)) + "\n");

  r = run_monitor({"replay", dir(), "--to-step", "99"}, scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "marsala-monitor: " + log_path() + " holds 12 steps; --to-step 99 is beyond it\n");

  for (const std::vector<std::string>& usage :
       std::vector<std::vector<std::string>>{{"replay"},
                                             {"replay", dir(), "--frames-every", "0"},
                                             {"replay", dir(), "--out", (dir_ / "f").string()},
                                             {"replay", dir(), "--to-step", "-1"},
                                             {"replay", dir(), "extra"}}) {
    r = run_monitor(usage, scratch);
    EXPECT_EQ(r.exit_code, 2) << usage.back();
    EXPECT_EQ(r.err.rfind("marsala-monitor: ", 0), 0u) << r.err;
  }

  fs::resize_file(log_path(), ends[8] + 4);
  r = run_monitor({"replay", dir()}, scratch);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.rfind("marsala-monitor: replayed the 9 good steps; " + log_path() + ": truncated record at byte " +
                            std::to_string(ends[8]),
                        0),
            0u)
      << r.err;
  EXPECT_EQ(r.out.substr(r.out.size() - 80),
            "terrain_sha256 " + runlog::terrain_sha256(apply_by_hand(plan(), 9)) + "\n");

  r = run_monitor({"replay", (dir_ / "nowhere").string()}, scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("nowhere/run.log"), std::string::npos) << r.err;

  r = run_monitor({"replay", "--help"}, scratch);
  EXPECT_EQ(r.exit_code, 0);
  for (const char* option : {"DIR", "--to-step", "--frames-every", "--out", "terrain_sha256"})
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
}

}  // namespace
}  // namespace marsala::monitor
