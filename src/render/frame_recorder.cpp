#include "vrdeform/render/frame_recorder.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/error.h"

extern char** environ;

namespace vrd {

FrameRecorder::FrameRecorder(const std::filesystem::path& dir, double fps) : dir_(dir), fps_(fps) {
  if (!(fps > 0.0 && fps <= 1000.0)) throw Error(fmt::format("frame recorder: {} frames per second", fps));
  std::error_code ec;
  std::filesystem::create_directories(dir_ / "frames", ec);
  if (ec) throw Error(fmt::format("{}: {}", (dir_ / "frames").string(), ec.message()));
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "frames", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("frame_") && name.ends_with(".png")) std::filesystem::remove(entry.path(), ec);
  }
}

void FrameRecorder::add(const Image& image) {
  if (frames_ == 0) {
    width_ = image.width;
    height_ = image.height;
  } else if (image.width != width_ || image.height != height_) {
    throw Error(
        fmt::format("frame recorder: a {}x{} frame in a {}x{} sequence", image.width, image.height, width_, height_));
  }
  writePng(dir_ / "frames" / fmt::format("frame_{:05}.png", frames_), image);
  ++frames_;
}

std::filesystem::path findOnPath(const char* program) {
  const char* path = std::getenv("PATH");
  if (!path) return {};
  std::string_view rest(path);
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    const std::string_view folder = rest.substr(0, colon);
    rest = colon == std::string_view::npos ? std::string_view() : rest.substr(colon + 1);
    if (folder.empty()) continue;
    const std::filesystem::path candidate = std::filesystem::path(folder) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

std::filesystem::path FrameRecorder::encodeVideo() const {
  const std::filesystem::path ffmpeg = findOnPath("ffmpeg");
  if (ffmpeg.empty() || frames_ == 0) return {};
  const std::filesystem::path video = dir_ / "video.mp4";
  // H.264 in yuv420p needs even sizes: the scale filter rounds down by at most a pixel.
  std::vector<std::string> args{ffmpeg.string(),
                                "-nostdin",
                                "-y",
                                "-loglevel",
                                "error",
                                "-framerate",
                                fmt::format("{:g}", fps_),
                                "-i",
                                (dir_ / "frames" / "frame_%05d.png").string(),
                                "-vf",
                                "scale=trunc(iw/2)*2:trunc(ih/2)*2",
                                "-pix_fmt",
                                "yuv420p",
                                video.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  pid_t pid = 0;
  const int failed = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (failed) throw Error(fmt::format("cannot run {}: {}", ffmpeg.string(), std::strerror(failed)));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error(fmt::format("ffmpeg could not make {} from {} frames (exit status {})", video.string(), frames_,
                            WIFEXITED(status) ? WEXITSTATUS(status) : -1));
  return video;
}

}  // namespace vrd
