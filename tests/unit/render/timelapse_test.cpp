#include "marsala/render/timelapse.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala::render {
namespace {

namespace fs = std::filesystem;

class Timelapse : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("marsala_timelapse_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

Image tiny() { return Image{2, 1, {255, 0, 0, 0, 0, 255}}; }

TEST_F(Timelapse, WritesAFrameEveryKStepsAndTheLastOnce) {
  FrameWriter frames((dir_ / "frames").string(), 3);
  int drawn = 0;
  const auto draw = [&] {
    ++drawn;
    return tiny();
  };
  for (std::uint64_t step = 0; step <= 10; ++step) frames.maybe_write(step, false, draw);
  frames.maybe_write(10, true, draw);
  frames.maybe_write(10, true, draw);  // the last step once only
  EXPECT_EQ(frames.names(), (std::vector<std::string>{"frame_000000.png", "frame_000003.png", "frame_000006.png",
                                                      "frame_000009.png", "frame_000010.png"}));
  EXPECT_EQ(drawn, 5);
  for (const std::string& name : frames.names()) EXPECT_GT(fs::file_size(dir_ / "frames" / name), 8u) << name;
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_ / "frames")) ++files;
  EXPECT_EQ(files, 5u);  // no temporaries left
}

TEST_F(Timelapse, ALastStepThatIsDueIsNotWrittenTwice) {
  FrameWriter frames(dir_.string(), 5);
  for (std::uint64_t step = 0; step <= 10; ++step) frames.maybe_write(step, false, tiny);
  frames.maybe_write(10, true, tiny);
  EXPECT_EQ(frames.names().size(), 3u);
}

TEST_F(Timelapse, AResumedTimeLapseContinuesTheFramesAlreadyThere) {
  {
    FrameWriter before(dir_.string(), 2);
    for (std::uint64_t step = 0; step <= 4; ++step) before.maybe_write(step, false, tiny);
  }
  std::ofstream(dir_ / "notes.txt") << "not a frame";
  FrameWriter after(dir_.string(), 2);
  EXPECT_EQ(after.names(), (std::vector<std::string>{"frame_000000.png", "frame_000002.png", "frame_000004.png"}));
  for (std::uint64_t step = 4; step <= 7; ++step) after.maybe_write(step, step == 7, tiny);  // 4 is drawn again
  EXPECT_EQ(after.names(), (std::vector<std::string>{"frame_000000.png", "frame_000002.png", "frame_000004.png",
                                                     "frame_000006.png", "frame_000007.png"}));
}

TEST_F(Timelapse, KZeroIsRefused) { EXPECT_THROW(FrameWriter(dir_.string(), 0), InvalidArgument); }

TEST_F(Timelapse, AFolderWithFramesIsRefusedNamingThem) {
  EXPECT_NO_THROW(check_fresh_frames_dir(dir_.string(), "a replay"));  // absent: fine
  fs::create_directories(dir_);
  std::ofstream(dir_ / "notes.txt") << "x";
  EXPECT_NO_THROW(check_fresh_frames_dir(dir_.string(), "a replay"));
  std::ofstream(dir_ / "frame_000007.png") << "x";
  try {
    check_fresh_frames_dir(dir_.string(), "another run's time-lapse");
    FAIL() << "a folder with a frame was accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("already holds another run's time-lapse (1 file, e.g. frame_000007.png)"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(Timelapse, NoFfmpegOnThePathSaysSo) {
  FrameWriter frames(dir_.string(), 1);
  frames.maybe_write(0, true, tiny);
  const TimelapseResult result = frames.finish("/nonexistent-dir");
  EXPECT_TRUE(result.path.empty());
  EXPECT_EQ(result.note, "skipped timelapse.mp4: ffmpeg is not installed (not on PATH)");
  EXPECT_EQ(find_ffmpeg(""), "");
}

}  // namespace
}  // namespace marsala::render
