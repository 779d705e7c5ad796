#pragma once
// A scene file's [solver] and [haptics] tables, read over the values a scene already has (a key left
// out keeps its value): a scene file reads them over the scene files' defaults, a study's condition
// over its scene's (docs/study.md). Every problem fails as the schema's do: "SOURCE:LINE: KEY: what".

#include "scene/toml_schema.h"
#include "vrdeform/scene/scene_spec.h"

namespace vrd {

void readSolverTable(const schema::Table& t, SolverSettings& s);
void readHapticsTable(const schema::Table& t, HapticsSpec& h);

}  // namespace vrd
