#pragma once
// A rendered sequence on disk: DIR/frames/frame_00000.png, frame_00001.png, ... and, when the
// ffmpeg program is on PATH, DIR/video.mp4 made from them (H.264, yuv420p, plays everywhere).

#include <cstddef>
#include <filesystem>

#include "vrdeform/render/image.h"

namespace vrd {

class FrameRecorder {
 public:
  /// Creates DIR/frames (removing the frame_*.png an earlier recording left there) for a sequence
  /// at `fps` frames per second. Throws vrd::Error for an fps outside (0, 1000] or a folder it
  /// cannot create.
  FrameRecorder(const std::filesystem::path& dir, double fps);

  /// Writes the next frame. Throws vrd::Error (a full disk, an image of another size).
  void add(const Image& image);
  std::size_t frames() const { return frames_; }
  const std::filesystem::path& dir() const { return dir_; }

  /// Runs ffmpeg on the frames when it is on PATH and there are frames; returns the video's path,
  /// or an empty one when there is no ffmpeg. Throws vrd::Error when ffmpeg fails.
  std::filesystem::path encodeVideo() const;

 private:
  std::filesystem::path dir_;
  double fps_;
  std::size_t frames_ = 0;
  int width_ = 0, height_ = 0;
};

/// The absolute path of `program` found on PATH, or an empty path.
std::filesystem::path findOnPath(const char* program);

}  // namespace vrd
