#pragma once
// Helpers shared by the tests.

#include <gtest/gtest.h>

#include <sstream>
#include <string>

namespace vrd::testing {

/// Records a measured value in the test report (--gtest_output=xml), so that a run documents the
/// figures behind its assertions.
inline void record(const std::string& key, double value) {
  std::ostringstream s;
  s.precision(6);
  s << value;
  ::testing::Test::RecordProperty(key, s.str());
}

}  // namespace vrd::testing
