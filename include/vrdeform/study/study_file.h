#pragma once
// Study files (docs/study.md): TOML read against the study schema, with `file:line: key: what`
// messages as scene files have.

#include <filesystem>
#include <string_view>

#include "vrdeform/study/study_spec.h"

namespace vrd {

/// Parses a study file's text; scene paths are relative to `baseDir`. Throws vrd::Error naming
/// `sourceName`, the line and the key of the first problem.
StudySpec parseStudy(std::string_view text, std::string_view sourceName, const std::filesystem::path& baseDir);

/// Reads and parses the study file at `path`. Throws vrd::Error.
StudySpec loadStudy(const std::filesystem::path& path);

}  // namespace vrd
