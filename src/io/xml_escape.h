#pragma once
// Text for XML content and double-quoted attributes (.vtu names, SVG labels).

#include <string>
#include <string_view>

namespace vrd {

/// Escapes & < > " and drops the control characters XML 1.0 does not allow (all but tab, newline
/// and carriage return).
std::string escapeXml(std::string_view text);

}  // namespace vrd
