#pragma once
// `vrdeform bench`: the paper's Tables 1-3 measured on the built-in scenes, next to the paper's
// figures; the liver's haptic loop at 1 kHz in real time; and solver scaling with tet count (SIMD
// lanes against the one-at-a-time loops).

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `bench` command; the returned function runs it and returns the exit code.
std::function<int()> addBenchCommand(CLI::App& app);

}  // namespace vrd
