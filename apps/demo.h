#pragma once
// The headless demo behind `vrdeform run` (until scene files arrive): a jelly cube dropped on
// the ground, poked by a fingertip, released; prints what happened and where the time went.

#include <string>

namespace vrd {

struct DemoOptions {
  float seconds = 4.0f;
  int substeps = 4;
  int iterations = 5;
  int tets = 1000;            ///< approximate tet count of the cube
  float reportEvery = 0.25f;  ///< seconds between timeline rows
  std::string savePath;       ///< .pvd to save frames to; empty: none
  float saveEvery = 1.0f / 30.0f;
};

/// Runs the demo, printing to stdout; returns the process exit code.
int runDemo(const DemoOptions& options);

}  // namespace vrd
