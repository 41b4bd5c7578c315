#pragma once
// A time-lapse of a run: PNG frames every K steps (and the last), named frame_<step, 6 digits>.png, and, when ffmpeg
// is installed, timelapse.mp4 of them at 10 frames/s. Used by marsala-world --frames-every and marsala-monitor replay
// --frames-every, so both write the same files. IO at the edge: files and one ffmpeg process.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "marsala/render/image.hpp"

namespace marsala::render {

/// "frame_000120.png" for step 120.
std::string frame_file_name(std::uint64_t step);

/// Throws IoError when `dir` exists and is no folder, or already holds frame_*.png or timelapse.mp4 (`what` names
/// what holds them, e.g. "a replay"): two time-lapses never mix.
void check_fresh_frames_dir(const std::string& dir, const std::string& what);

/// The first executable "ffmpeg" in the colon-separated `search_path` (e.g. $PATH), or empty.
std::string find_ffmpeg(const std::string& search_path);

/// Assembles frames_dir/timelapse.mp4 from `frames` (file names in frames_dir, in step order) with `ffmpeg` at 10
/// frames/s, padded white to width_px x height_px (rounded up to even) [px]; throws IoError when ffmpeg fails.
void write_timelapse(const std::string& ffmpeg, const std::string& frames_dir, const std::vector<std::string>& frames,
                     int width_px, int height_px);

/// What FrameWriter::finish() made.
struct TimelapseResult {
  std::string path;      ///< timelapse.mp4, or empty when none was made
  std::string note;      ///< why none was made (ffmpeg not installed)
  double seconds = 0.0;  ///< wall time of ffmpeg [s]
};

/// Writes the frames of one time-lapse into a folder it creates: one every `every` steps (>= 1) and the last, each
/// step at most once, each file written to "<name>.tmp" and renamed. Frames already in the folder (a resumed run's)
/// are part of it: in names() and in timelapse.mp4; one drawn again replaces its file.
class FrameWriter {
 public:
  /// Creates `dir` (throws IoError when it cannot).
  FrameWriter(std::string dir, std::uint64_t every);

  /// When `step` is due (a multiple of every, or `last`) and not drawn yet, draws it with `draw` and writes it.
  void maybe_write(std::uint64_t step, bool last, const std::function<Image()>& draw);

  /// Makes timelapse.mp4 with the ffmpeg found in `search_path`, or says why not.
  TimelapseResult finish(const std::string& search_path) const;

  const std::vector<std::string>& names() const { return names_; }
  const std::string& dir() const { return dir_; }
  double seconds() const { return seconds_; }  ///< drawing and writing frames [s]

 private:
  std::string dir_;
  std::uint64_t every_;
  std::optional<std::uint64_t> written_;
  std::vector<std::string> names_;
  int width_px_ = 0;
  int height_px_ = 0;
  double seconds_ = 0.0;
};

}  // namespace marsala::render
