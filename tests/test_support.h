#pragma once
// Helpers shared by the tests.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/error.h"

namespace vrd::testing {

constexpr float kG = 9.81f;  ///< m/s^2, standard gravity as the scenes use it

/// Spacing of the float grid at x (one ulp).
inline double ulp(float x) {
  const float a = std::fabs(x);
  return double(std::nextafter(a, std::numeric_limits<float>::infinity())) - double(a);
}

/// Records a measured value in the test report (--gtest_output=xml), so that a run documents the
/// figures behind its assertions.
inline void record(const std::string& key, double value) {
  std::ostringstream s;
  s.precision(6);
  s << value;
  ::testing::Test::RecordProperty(key, s.str());
}

/// Runs f, expects a vrd::Error, and returns its message (a failure and "" otherwise).
template <typename F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a vrd::Error: " << e.what();
    return {};
  }
  ADD_FAILURE() << "no vrd::Error thrown";
  return {};
}

/// A random edit of `text` for fuzzing a parser: one byte replaced by a random one, one character
/// of `alphabet` inserted, or 1-8 bytes erased.
template <typename Rng>
std::string mutate(std::string text, Rng& rng, std::string_view alphabet) {
  if (text.empty()) return text;
  const std::size_t at = rng() % text.size();
  switch (rng() % 3) {
    case 0:
      text[at] = static_cast<char>(rng());
      break;
    case 1:
      text.insert(at, 1, alphabet[rng() % alphabet.size()]);
      break;
    default:
      text.erase(at, 1 + rng() % 8);
      break;
  }
  return text;
}

/// The meshes shipped beside the repository (../shared/data/meshes).
inline const std::filesystem::path kMeshes = std::filesystem::path(VRDEFORM_SHARED_DIR) / "data" / "meshes";

/// A file's bytes ("" when it cannot be read).
inline std::string readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Writes a new file (not a truncated one: ext4 flushes a file rewritten after truncation when it
/// is closed, which costs milliseconds each time).
inline void writeBytes(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::remove(path);
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

/// Participant k's folder (P1, P2, ...) in a study's data folder. (Appended rather than "P" + ...:
/// GCC 12 reports a false -Wrestrict on that once it is inlined into some callers.)
inline std::filesystem::path participantFolder(const std::filesystem::path& data, int k) {
  std::string name = "P";
  name += std::to_string(k);
  return data / name;
}

/// A fresh folder under the system's temporary folder, removed with its contents afterwards.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("vrdeform_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  /// The names in the folder, sorted.
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path_))
      names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::filesystem::path path_;
};

/// A path in a folder of this test process that is removed when the process ends.
inline std::filesystem::path scratchPath(const std::string& name) {
  static const TempDir dir;
  return dir / name;
}

}  // namespace vrd::testing
