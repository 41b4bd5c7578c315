#include "marsala/render/timelapse.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <utility>

#include <fmt/format.h>

#include "marsala/core/error.hpp"
#include "marsala/render/png_writer.hpp"
#include "marsala/runlog/atomic_file.hpp"

extern char** environ;

namespace marsala::render {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// Runs argv[0] with argv, its output on ours; returns its exit status (128 + signal when killed).
int run_program(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (::posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0)
    throw IoError(fmt::format("cannot start '{}'", args[0]));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw IoError(fmt::format("cannot wait for '{}'", args[0]));
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

std::string frame_file_name(std::uint64_t step) { return fmt::format("frame_{:06}.png", step); }

void check_fresh_frames_dir(const std::string& dir, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return;
  if (!fs::is_directory(dir, ec)) throw IoError(fmt::format("frames folder '{}' is not a folder", dir));
  std::vector<std::string> found;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const bool frame = name.size() > 10 && name.rfind("frame_", 0) == 0 && name.substr(name.size() - 4) == ".png";
    if (frame || name == "timelapse.mp4") found.push_back(name);
  }
  if (ec) throw IoError(fmt::format("cannot list frames folder '{}': {}", dir, ec.message()));
  if (found.empty()) return;
  std::sort(found.begin(), found.end());
  throw IoError(fmt::format("frames folder '{}' already holds {} ({} file{}, e.g. {}); give another --out or empty it",
                            dir, what, found.size(), found.size() == 1 ? "" : "s", found.front()));
}

std::string find_ffmpeg(const std::string& search_path) {
  std::size_t begin = 0;
  while (begin <= search_path.size() && !search_path.empty()) {
    const std::size_t end = std::min(search_path.find(':', begin), search_path.size());
    const std::string dir = search_path.substr(begin, end - begin);
    if (!dir.empty()) {
      const std::string candidate = (fs::path(dir) / "ffmpeg").string();
      if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    begin = end + 1;
  }
  return {};
}

// The frames' step numbers are not consecutive, so ffmpeg reads numbered links to them from a scratch folder; frames
// of different sizes (a legend that grew) are padded to the largest.
void write_timelapse(const std::string& ffmpeg, const std::string& frames_dir, const std::vector<std::string>& frames,
                     int width_px, int height_px) {
  const fs::path scratch = fs::path(frames_dir) / ".timelapse_frames";
  std::error_code ec;
  fs::remove_all(scratch, ec);
  fs::create_directories(scratch, ec);
  if (ec) throw IoError(fmt::format("cannot create '{}': {}", scratch.string(), ec.message()));
  for (std::size_t k = 0; k < frames.size(); ++k) {
    fs::create_symlink(fs::path("..") / frames[k], scratch / fmt::format("{:06}.png", k), ec);
    if (ec) throw IoError(fmt::format("cannot link '{}' in '{}': {}", frames[k], scratch.string(), ec.message()));
  }
  const std::string out = (fs::path(frames_dir) / "timelapse.mp4").string();
  try {
    runlog::write_atomically(out, [&](const std::string& tmp) {
      const int status = run_program(
          {ffmpeg, "-y", "-loglevel", "error", "-framerate", "10", "-i", (scratch / "%06d.png").string(), "-pix_fmt",
           "yuv420p", "-vf", fmt::format("pad={}:{}:0:0:white", width_px + width_px % 2, height_px + height_px % 2),
           "-f", "mp4", tmp});
      if (status != 0) throw IoError(fmt::format("ffmpeg failed (exit {}) making '{}'", status, out));
    });
  } catch (...) {
    fs::remove_all(scratch, ec);
    throw;
  }
  fs::remove_all(scratch, ec);
}

FrameWriter::FrameWriter(std::string dir, std::uint64_t every) : dir_(std::move(dir)), every_(every) {
  if (every_ == 0) throw InvalidArgument("a frame every 0 steps: K must be at least 1");
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw IoError(fmt::format("cannot create frames folder '{}': {}", dir_, ec.message()));
  // Frames already there (a resumed run's) belong to the same time-lapse: in step order (the names sort so), and
  // their sizes count for the video's.
  for (const fs::directory_entry& e : fs::directory_iterator(dir_, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() != frame_file_name(0).size() || name.rfind("frame_", 0) != 0 || e.path().extension() != ".png")
      continue;
    names_.push_back(name);
    std::ifstream in(e.path(), std::ios::binary);
    unsigned char header[24] = {};
    if (in.read(reinterpret_cast<char*>(header), sizeof header)) {  // PNG: IHDR's width and height, big-endian
      const auto be32 = [&](int at) {
        return static_cast<int>((header[at] << 24) | (header[at + 1] << 16) | (header[at + 2] << 8) | header[at + 3]);
      };
      width_px_ = std::max(width_px_, be32(16));
      height_px_ = std::max(height_px_, be32(20));
    }
  }
  if (ec) throw IoError(fmt::format("cannot list frames folder '{}': {}", dir_, ec.message()));
  std::sort(names_.begin(), names_.end());
}

void FrameWriter::maybe_write(std::uint64_t step, bool last, const std::function<Image()>& draw) {
  if (written_ && *written_ == step) return;
  if (!last && step % every_ != 0) return;
  const auto start = Clock::now();
  const Image image = draw();
  const std::string name = frame_file_name(step);
  runlog::write_atomically((fs::path(dir_) / name).string(), [&](const std::string& tmp) { write_png(image, tmp); });
  if (std::find(names_.begin(), names_.end(), name) == names_.end()) names_.push_back(name);  // redrawn: once
  width_px_ = std::max(width_px_, image.width);
  height_px_ = std::max(height_px_, image.height);
  written_ = step;
  seconds_ += seconds_since(start);
}

TimelapseResult FrameWriter::finish(const std::string& search_path) const {
  TimelapseResult result;
  const std::string ffmpeg = find_ffmpeg(search_path);
  if (ffmpeg.empty()) {
    result.note = "skipped timelapse.mp4: ffmpeg is not installed (not on PATH)";
    return result;
  }
  const auto start = Clock::now();
  write_timelapse(ffmpeg, dir_, names_, width_px_, height_px_);
  result.seconds = seconds_since(start);
  result.path = (fs::path(dir_) / "timelapse.mp4").string();
  return result;
}

}  // namespace marsala::render
