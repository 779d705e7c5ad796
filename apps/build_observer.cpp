#include "build_observer.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

namespace vrd {

void printSceneTitle(const SceneSpec& spec) {
  fmt::print("scene {}{}{}\n", spec.name, spec.description.empty() ? "" : ": ", spec.description);
}

SceneBuildObserver commandObserver(const StopSignals& signals, bool print) {
  SceneBuildObserver o;
  o.stop = [&signals] { return signals.requested(); };
  if (!print) return o;
  // The bar is on one line that each update rewrites; a log line after it starts a new line.
  auto bar = std::make_shared<bool>(false);
  o.log = [bar](std::string_view line) {
    if (*bar) fmt::print("\n");
    *bar = false;
    fmt::print("{}\n", line);
  };
  if (::isatty(STDOUT_FILENO) != 1) return o;
  o.settling = [bar, last = std::make_shared<int>(-1)](double done, double total) {
    const int width = 40, filled = total > 0 ? int(std::clamp(done / total, 0.0, 1.0) * width) : width;
    if (filled == *last) return;
    *last = filled, *bar = true;
    fmt::print("\r  settling [{}{}] {:.2f} / {:g} s ", std::string(filled, '#'), std::string(width - filled, ' '), done,
               total);
    std::fflush(stdout);
  };
  return o;
}

}  // namespace vrd
