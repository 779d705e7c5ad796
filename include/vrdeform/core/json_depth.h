#pragma once
// A guard for untrusted JSON (the glove's middleware, the VR page): nesting is checked before
// parsing, because a recursive parser given "[[[[..." would exhaust the stack.

#include <string_view>

namespace vrd {

/// Whether the brackets of `text` (those outside strings) nest at most `maxDepth` deep.
bool jsonDepthWithin(std::string_view text, int maxDepth);

}  // namespace vrd
