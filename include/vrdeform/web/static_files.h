#pragma once
// The files the VR server serves: the page (web/public) and the parts of three.js it imports
// (web/node_modules/three), found in the source tree during development and under
// share/vrdeform/web once installed; request paths mapped onto them without ever leaving them.

#include <filesystem>
#include <optional>
#include <string_view>

namespace vrd {

/// The web folder (holding public/ and node_modules/three/): $VRDEFORM_WEB if set, else the
/// source tree's web/ (a build), else <prefix>/share/vrdeform/web next to the installed program.
/// Throws vrd::Error when none holds public/index.html.
std::filesystem::path webFolder();

/// Whether `web` holds three.js (scripts/install-web.sh puts it there in a source tree).
bool hasThreeJs(const std::filesystem::path& web);

/// The file a request target (path, optionally with a query) names: "/" and "/x/" are
/// public/index.html and public/x/index.html, "/three/build/..." and "/three/examples/jsm/..." are
/// three.js's files, anything else is under public/. nullopt for a target that is malformed (bad
/// percent escapes, NUL, backslashes, empty, "." or ".." segments), that leaves its folder through
/// a link, or that names no regular file.
std::optional<std::filesystem::path> resolveStaticPath(const std::filesystem::path& web, std::string_view target);

/// The Content-Type for a file name's extension (application/octet-stream for unknown ones).
std::string_view mimeType(const std::filesystem::path& file);

}  // namespace vrd
