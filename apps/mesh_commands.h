#pragma once
// `vrdeform mesh ...`: check, tetrahedralise, measure, convert and compare meshes.

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `mesh` command group to `app`. The returned function runs whichever mesh command
/// was given and returns the process exit code (0 fine, 1 the mesh has defects, 2 bad input;
/// `mesh IN OUT`: 0 fine, 1 with a one-line reason for any failure).
std::function<int()> addMeshCommands(CLI::App& app);

}  // namespace vrd
