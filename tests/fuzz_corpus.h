#pragma once
// The fuzz targets' seed and regression inputs (tests/fuzz_corpus/<target>/, scripts/fuzz.sh),
// fed to the parsers by the unit tests. A file's name says what the parser must make of it:
// ok_* parses, bad_* is refused with a vrd::Error (the inputs a fuzzer found keep the name of
// what they broke, e.g. bad_nan_list_count).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

#include "test_support.h"

namespace vrd::testing {

/// Calls parse(bytes) for every file of tests/fuzz_corpus/<target>, expecting it to return for ok_*
/// files and to throw vrd::Error for bad_* files; fails for any other name and for a corpus without
/// both kinds (the seeds are ok_, and every target has at least one bad_ example).
template <typename Parse>
void checkCorpus(std::string_view target, Parse&& parse) {
  const std::filesystem::path dir = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / "fuzz_corpus" / target;
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  int ok = 0, bad = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    SCOPED_TRACE(entry.path().string());
    if (name.starts_with("ok_")) {
      try {
        parse(bytes);
      } catch (const std::exception& e) {
        ADD_FAILURE() << "refused: " << e.what();
      }
      ++ok;
    } else if (name.starts_with("bad_")) {
      EXPECT_FALSE(errorOf([&] { parse(bytes); }).empty());
      ++bad;
    } else {
      ADD_FAILURE() << "a corpus file's name starts with ok_ or bad_";
    }
  }
  EXPECT_GT(ok, 0);
  EXPECT_GT(bad, 0);
}

}  // namespace vrd::testing
