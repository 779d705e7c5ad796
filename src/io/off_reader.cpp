#include "io/off_reader.h"

#include <fmt/format.h>

#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd {

TriMesh readOff(std::string_view text, const std::string& name) {
  io::TextTokens in(text, name, '#');
  if (in.atEnd()) in.fail("the file is empty, expected OFF and the numbers of vertices and faces");
  bool homogeneous = false;
  if (const std::string_view keyword = in.peek(); keyword.ends_with("OFF")) {
    in.next("the header");
    std::string_view prefix = keyword.substr(0, keyword.size() - 3);
    for (const std::string_view flag : {"ST", "C", "N", "4"})
      if (prefix.starts_with(flag)) {
        homogeneous = flag == "4";
        prefix.remove_prefix(flag.size());
      }
    if (prefix == "n") in.fail("nOFF (vertices of any dimension) is not supported, only 3D OFF");
    if (!prefix.empty()) in.fail(fmt::format("unknown header '{}', expected [ST][C][N][4]OFF", io::printable(keyword)));
  }
  // Each vertex takes at least 3 tokens and each face 1 (its corner count).
  const std::size_t vertexCount = in.count("the number of vertices", homogeneous ? 4 : 3);
  const std::size_t faceCount = in.count("the number of faces", 1);
  in.restOfLine();  // the number of edges, which nothing needs

  TriMesh mesh;
  mesh.vertices.resize(vertexCount);
  for (Vec3& v : mesh.vertices) {
    double x[4] = {0, 0, 0, 1};
    for (int k = 0; k < (homogeneous ? 4 : 3); ++k) x[k] = in.real32("vertex coordinate");
    v = Vec3(static_cast<float>(x[0] / x[3]), static_cast<float>(x[1] / x[3]), static_cast<float>(x[2] / x[3]));
    in.restOfLine();  // normal, colour, texture coordinates
  }
  for (std::size_t f = 0; f < faceCount; ++f) {
    const std::size_t corners = in.count("the number of corners of a face", 1);
    Index first = 0, previous = 0;
    for (std::size_t k = 0; k < corners; ++k) {
      const auto i = static_cast<Index>(in.integer("a vertex index", 0, static_cast<std::int64_t>(vertexCount) - 1));
      if (k == 0) first = i;
      if (k >= 2) mesh.triangles.push_back({first, previous, i});  // a fan
      previous = i;
    }
    in.restOfLine();  // a face colour
  }
  return mesh;
}

}  // namespace vrd
