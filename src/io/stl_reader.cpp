#include "io/stl_reader.h"

#include <fmt/format.h>

#include <bit>
#include <cctype>
#include <cstdint>

#include "io/binary.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

constexpr std::size_t kHeader = 84, kFacet = 50;

TriMesh readBinary(std::string_view bytes, std::uint64_t facets) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + kHeader;
  TriMesh mesh;
  mesh.vertices.reserve(3 * facets);
  mesh.triangles.reserve(facets);
  for (std::uint64_t f = 0; f < facets; ++f, p += kFacet) {
    const auto first = static_cast<Index>(mesh.vertices.size());
    for (int corner = 1; corner <= 3; ++corner) {  // after the normal
      Vec3 v;
      for (int k = 0; k < 3; ++k)
        v[k] = std::bit_cast<float>(std::uint32_t(io::loadUnsigned(p + 12 * corner + 4 * k, 4, false)));
      mesh.vertices.push_back(v);
    }
    mesh.triangles.push_back({first, first + 1, first + 2});
  }
  return mesh;
}

void expect(io::TextTokens& in, std::string_view keyword) {
  const std::string_view token = in.next(keyword);
  if (token != keyword) in.fail(fmt::format("expected '{}', found '{}'", keyword, io::printable(token)));
}

TriMesh readAscii(std::string_view text, const std::string& name) {
  io::TextTokens in(text, name);
  TriMesh mesh;
  while (!in.atEnd()) {
    expect(in, "solid");
    in.restOfLine();  // the solid's name
    while (true) {
      if (in.atEnd()) return mesh;  // some writers leave out the last endsolid
      const std::string_view token = in.next("facet or endsolid");
      if (token == "endsolid") {
        in.restOfLine();
        break;
      }
      if (token != "facet") in.fail(fmt::format("expected 'facet' or 'endsolid', found '{}'", io::printable(token)));
      expect(in, "normal");
      for (int k = 0; k < 3; ++k) in.real("a normal component");
      expect(in, "outer");
      expect(in, "loop");
      const auto first = static_cast<Index>(mesh.vertices.size());
      while (in.peek() == "vertex") {
        in.next("vertex");
        Vec3 v;
        for (int k = 0; k < 3; ++k) v[k] = in.real32("vertex coordinate");
        mesh.vertices.push_back(v);
      }
      const auto corners = static_cast<Index>(mesh.vertices.size()) - first;
      if (corners < 3) in.fail(fmt::format("a facet needs at least 3 vertices, found {}", corners));
      for (Index k = 2; k < corners; ++k) mesh.triangles.push_back({first, first + k - 1, first + k});  // a fan
      expect(in, "endloop");
      expect(in, "endfacet");
    }
  }
  return mesh;
}

}  // namespace

TriMesh readStl(std::string_view bytes, const std::string& name) {
  // The count a binary header would hold (0 for a file too short to have one).
  const std::uint64_t facets =
      bytes.size() < kHeader ? 0
                             : io::loadUnsigned(reinterpret_cast<const unsigned char*>(bytes.data()) + 80, 4, false);
  if (bytes.size() >= kHeader && bytes.size() == kHeader + kFacet * facets) return readBinary(bytes, facets);
  std::size_t start = 0;
  while (start < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[start]))) ++start;
  if (bytes.substr(start, 5) == "solid") return readAscii(bytes, name);
  if (bytes.size() < kHeader)
    throw Error(fmt::format("{}: {} bytes: too short for a binary STL (84) and not ASCII STL (no 'solid')", name,
                            bytes.size()));
  throw Error(fmt::format("{}: a binary STL of {} facets takes {} bytes, the file has {} (truncated or not STL)", name,
                          facets, kHeader + kFacet * facets, bytes.size()));
}

}  // namespace vrd
