#pragma once
// Messages number vertices, faces and tets from 1, as a user counts them and as OBJ and Medit files
// do; the meshes and reports keep 0-based ids.

#include <fmt/format.h>

#include <cstddef>
#include <string>

#include "vrdeform/math/types.h"

namespace vrd {

inline std::size_t oneBased(std::size_t id) { return id + 1; }

/// "a, b, c" for 0-based ids, numbered from 1.
template <typename Ids>
std::string oneBasedList(const Ids& ids) {
  std::string out;
  for (const auto id : ids) out += fmt::format("{}{}", out.empty() ? "" : ", ", oneBased(std::size_t(id)));
  return out;
}

}  // namespace vrd
