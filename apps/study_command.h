#pragma once
// `vrdeform study`: a within-subject haptics study from its study file (docs/study.md): `check`
// reads the file and prints the plan and each participant's order of the conditions, `analyse`
// turns the participants' answers into statistics and a report.

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `study` command to `app`. The returned function runs it and returns the exit code (0
/// fine); vrd::Error (bad input) propagates, reported as 2.
std::function<int()> addStudyCommand(CLI::App& app);

}  // namespace vrd
