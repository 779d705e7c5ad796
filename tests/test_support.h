#pragma once
// Helpers shared by the tests.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/error.h"

namespace vrd::testing {

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
