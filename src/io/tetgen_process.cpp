// TetGen as a child process: the surface goes out as .smesh, the mesh comes back as .node/.ele.
#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ostream.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <thread>

#include "vrdeform/core/atomic_file.h"
#include "vrdeform/error.h"
#include "vrdeform/io/tet_io.h"
#include "vrdeform/io/tetrahedralise.h"

extern char** environ;

namespace vrd {
namespace {

namespace fs = std::filesystem;

// A scratch folder that is removed with everything in it.
struct ScratchFolder {
  fs::path path;
  ScratchFolder() {
    std::string pattern = (fs::temp_directory_path() / "vrdeform-tetgen-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw Error("cannot create a scratch folder for TetGen");
    path = pattern;
  }
  ~ScratchFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

void writeSmesh(const fs::path& path, const TriMesh& surface) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  fmt::print(out, "{} 3 0 0\n", surface.vertices.size());
  for (std::size_t v = 0; v < surface.vertices.size(); ++v) {
    const Vec3& p = surface.vertices[v];
    fmt::print(out, "{} {:.9g} {:.9g} {:.9g}\n", v, p.x(), p.y(), p.z());
  }
  fmt::print(out, "{} 0\n", surface.triangles.size());
  for (const Triangle& t : surface.triangles) fmt::print(out, "3 {} {} {}\n", t[0], t[1], t[2]);
  out << "0\n0\n";  // no holes, no regions
  file.commit();
}

std::string lastLines(const fs::path& log, std::size_t count) {
  std::ifstream in(log);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  const std::size_t first = lines.size() > count ? lines.size() - count : 0;
  std::string text;
  for (std::size_t k = first; k < lines.size(); ++k) text += "\n  " + lines[k];
  return text.empty() ? " (no output)" : text;
}

}  // namespace

TetMesh runTetGen(const TriMesh& surface, double maxVolume, double radiusEdge, const TetrahedraliseOptions& options) {
  ScratchFolder scratch;
  const fs::path input = scratch.path / "surface.smesh", log = scratch.path / "tetgen.log";
  writeSmesh(input, surface);

  std::string switches = "-p";
  if (radiusEdge > 0) switches += fmt::format("q{:.6g}", radiusEdge);
  if (maxVolume > 0) switches += fmt::format("a{:.9g}", maxVolume);
  switches += "zQ";
  std::string program = options.tetgenProgram, inputName = input.string();
  char* argv[] = {program.data(), const_cast<char*>(switches.c_str()), inputName.data(), nullptr};

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int spawnError = ::posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawnError != 0)
    throw Error(
        fmt::format("cannot run TetGen ('{}': {}); install it (Debian package tetgen) or use the built-in mesher",
                    program, std::strerror(spawnError)));

  // Wait, polling, so a hung TetGen is killed after the timeout, or when the caller stops.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(options.timeoutSeconds);
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) throw Error(fmt::format("lost track of TetGen: {}", std::strerror(errno)));
    if (options.stop && options.stop()) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      throw Stopped("stopped while meshing (TetGen stopped)");
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      throw Error(fmt::format("TetGen did not finish within {} s ({} {}){}", options.timeoutSeconds, program, switches,
                              lastLines(log, 5)));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (WIFSIGNALED(status))
    throw Error(fmt::format("TetGen crashed (signal {}: {}) on this surface ({} {}){}", WTERMSIG(status),
                            ::strsignal(WTERMSIG(status)), program, switches, lastLines(log, 5)));
  if (WEXITSTATUS(status) != 0)
    throw Error(fmt::format("TetGen failed (exit status {}) on this surface ({} {}){}", WEXITSTATUS(status), program,
                            switches, lastLines(log, 5)));
  TetMesh mesh;
  try {
    mesh = readTetMesh(scratch.path / "surface.1.node");
  } catch (const Error& e) {
    throw Error(fmt::format("TetGen's output could not be read: {}{}", e.what(), lastLines(log, 5)));
  }
  // Debian's TetGen writes positive tets; other builds of the program need not, and the engine
  // requires them.
  for (Tet& tet : mesh.tets) {
    const auto p = [&](int k) -> Vec3d { return mesh.vertices[tet[k]].cast<double>(); };
    if (signedTetVolume(p(0), p(1), p(2), p(3)) < 0) std::swap(tet[2], tet[3]);
  }
  return mesh;
}

}  // namespace vrd
