#pragma once
// Helpers shared by the tests.

#include <gtest/gtest.h>

#include <sstream>
#include <string>

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

}  // namespace vrd::testing
