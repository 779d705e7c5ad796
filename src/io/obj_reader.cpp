#include "io/obj_reader.h"

#include <fmt/format.h>

#include <vector>

#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

// The words of one line, up to a comment.
std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  io::splitWords(line.substr(0, line.find('#')), out);
  return out;
}

float coordinate(const io::TextTokens& in, std::string_view word) {
  double x = 0.0;
  if (!io::parseReal(word, x)) in.fail(fmt::format("'{}' is not a vertex coordinate", io::printable(word)));
  return in.toFloat(x, word, "vertex coordinate");
}

// A face corner's vertex: the number before the first '/', 1-based, or negative from the last vertex.
Index corner(const io::TextTokens& in, std::string_view word, std::size_t vertexCount) {
  const std::string_view number = word.substr(0, word.find('/'));
  std::int64_t i = 0;
  if (!io::parseInteger(number, i)) in.fail(fmt::format("'{}' is not a face corner", io::printable(word)));
  const auto n = static_cast<std::int64_t>(vertexCount);
  if (i == 0) in.fail("face corner 0: OBJ numbers vertices from 1");
  if (i > n || i < -n)
    in.fail(fmt::format("face corner {} refers to a vertex not defined above it ({} so far)", i, vertexCount));
  return static_cast<Index>(i > 0 ? i - 1 : n + i);
}

}  // namespace

TriMesh readObj(std::string_view text, const std::string& name) {
  io::TextTokens in(text, name, '#');
  TriMesh mesh;
  std::string joined;
  while (!in.atEnd()) {
    const std::string_view keyword = in.next("a keyword");
    std::string_view line = in.restOfLine();
    if (line.ends_with('\\')) {  // continued on the next lines
      joined.assign(line.substr(0, line.size() - 1));
      while (true) {
        if (in.remaining() == 0) break;
        const std::string_view more = in.restOfLine();
        joined += ' ';
        joined += more.ends_with('\\') ? more.substr(0, more.size() - 1) : more;
        if (!more.ends_with('\\')) break;
      }
      line = joined;
    }
    if (keyword == "v") {
      const std::vector<std::string_view> x = words(line);
      if (x.size() < 3) in.fail(fmt::format("a vertex needs 3 coordinates, found {}", x.size()));
      mesh.vertices.emplace_back(coordinate(in, x[0]), coordinate(in, x[1]), coordinate(in, x[2]));
    } else if (keyword == "f") {
      const std::vector<std::string_view> corners = words(line);
      if (corners.size() < 3) in.fail(fmt::format("a face needs at least 3 corners, found {}", corners.size()));
      const Index first = corner(in, corners[0], mesh.vertices.size());
      Index previous = corner(in, corners[1], mesh.vertices.size());
      for (std::size_t k = 2; k < corners.size(); ++k) {  // a fan
        const Index next = corner(in, corners[k], mesh.vertices.size());
        mesh.triangles.push_back({first, previous, next});
        previous = next;
      }
    }
    // Anything else (vt, vn, g, o, s, usemtl, mtllib, l, p, curves, ...) carries no surface geometry.
  }
  return mesh;
}

}  // namespace vrd
