#include "vrdeform/io/surface_io.h"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <bit>
#include <fstream>
#include <unordered_map>

#include "io/binary.h"
#include "io/extension.h"
#include "io/obj_reader.h"
#include "io/off_reader.h"
#include "io/ply_reader.h"
#include "io/stl_reader.h"
#include "vrdeform/core/atomic_file.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

struct PositionKey {
  std::uint32_t x, y, z;
  bool operator==(const PositionKey&) const = default;
};

struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    return (std::size_t{k.x} * 73856093u) ^ (std::size_t{k.y} * 19349663u) ^ (std::size_t{k.z} * 83492791u);
  }
};

// +0 and -0 are one position.
PositionKey keyOf(const Vec3& p) {
  return {std::bit_cast<std::uint32_t>(p.x() + 0.0f), std::bit_cast<std::uint32_t>(p.y() + 0.0f),
          std::bit_cast<std::uint32_t>(p.z() + 0.0f)};
}

// Corners at one position become one vertex, numbered in order of first use.
TriMesh weld(const TriMesh& raw, const std::string& name) {
  TriMesh mesh;
  std::unordered_map<PositionKey, Index, PositionHash> indexOf;
  for (std::size_t t = 0; t < raw.triangles.size(); ++t) {
    Triangle triangle;
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = raw.vertices[raw.triangles[t][k]];
      if (!isFinite(p))
        throw Error(fmt::format("{}: face {} has a non-finite vertex ({}, {}, {})", name, t + 1, p.x(), p.y(), p.z()));
      const auto [it, added] = indexOf.try_emplace(keyOf(p), static_cast<Index>(mesh.vertices.size()));
      if (added) mesh.vertices.push_back(p);
      triangle[k] = it->second;
    }
    mesh.triangles.push_back(triangle);
  }
  if (mesh.triangles.empty()) throw Error(fmt::format("{}: the file holds no triangles", name));
  return mesh;
}

}  // namespace

bool isSurfaceFile(const std::filesystem::path& path) {
  const std::string ext = io::lowerExtension(path);
  return ext == ".obj" || ext == ".off" || ext == ".stl" || ext == ".ply";
}

TriMesh readSurface(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string ext = io::lowerExtension(path);
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (std::filesystem::is_directory(status)) throw Error(fmt::format("{}: is a folder, not a mesh file", name));
  if (!std::filesystem::is_regular_file(status)) throw Error(fmt::format("{}: no such file", name));
  if (std::filesystem::file_size(path, error) == 0) throw Error(fmt::format("{}: the file is empty", name));
  if (!isSurfaceFile(path))
    throw Error(fmt::format("{}: unknown surface format '{}' (use .obj, .off, .stl or .ply)", name, ext));
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), {}};
  if (!in && !in.eof()) throw Error(fmt::format("{}: cannot read the file", name));
  if (ext == ".ply") return weld(readPly(path, bytes), name);
  if (ext == ".off") return weld(readOff(bytes, name), name);
  if (ext == ".stl") return weld(readStl(bytes, name), name);
  return weld(readObj(bytes, name), name);
}

namespace {

void writeObj(std::ostream& out, const TriMesh& mesh) {
  fmt::print(out, "# vrdeform surface: {} vertices, {} triangles\n", mesh.vertices.size(), mesh.triangles.size());
  for (const Vec3& p : mesh.vertices) fmt::print(out, "v {:.9g} {:.9g} {:.9g}\n", p.x(), p.y(), p.z());
  for (const Triangle& t : mesh.triangles) fmt::print(out, "f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
}

void writeOff(std::ostream& out, const TriMesh& mesh) {
  fmt::print(out, "OFF\n{} {} 0\n", mesh.vertices.size(), mesh.triangles.size());
  for (const Vec3& p : mesh.vertices) fmt::print(out, "{:.9g} {:.9g} {:.9g}\n", p.x(), p.y(), p.z());
  for (const Triangle& t : mesh.triangles) fmt::print(out, "3 {} {} {}\n", t[0], t[1], t[2]);
}

Vec3 faceNormal(const TriMesh& mesh, const Triangle& t) {
  const Vec3& a = mesh.vertices[t[0]];
  return (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).normalized();
}

void writeStl(std::ostream& out, const TriMesh& mesh, bool binary) {
  if (!binary) {
    out << "solid vrdeform\n";
    for (const Triangle& t : mesh.triangles) {
      const Vec3 n = faceNormal(mesh, t);
      fmt::print(out, "facet normal {:.9g} {:.9g} {:.9g}\n outer loop\n", n.x(), n.y(), n.z());
      for (Index v : t) {
        const Vec3& p = mesh.vertices[v];
        fmt::print(out, "  vertex {:.9g} {:.9g} {:.9g}\n", p.x(), p.y(), p.z());
      }
      out << " endloop\nendfacet\n";
    }
    out << "endsolid vrdeform\n";
    return;
  }
  std::string bytes = "vrdeform binary STL";
  bytes.resize(80, '\0');
  io::storeLittle(bytes, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const Triangle& t : mesh.triangles) {
    const Vec3 n = faceNormal(mesh, t);
    for (int k = 0; k < 3; ++k) io::storeLittle(bytes, n[k]);
    for (Index v : t)
      for (int k = 0; k < 3; ++k) io::storeLittle(bytes, mesh.vertices[v][k]);
    bytes += std::string(2, '\0');  // attribute byte count
  }
  out << bytes;
}

void writePly(std::ostream& out, const TriMesh& mesh, bool binary) {
  fmt::print(out,
             "ply\nformat {} 1.0\ncomment vrdeform surface\nelement vertex {}\nproperty float x\nproperty float y\n"
             "property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
             binary ? "binary_little_endian" : "ascii", mesh.vertices.size(), mesh.triangles.size());
  if (!binary) {
    for (const Vec3& p : mesh.vertices) fmt::print(out, "{:.9g} {:.9g} {:.9g}\n", p.x(), p.y(), p.z());
    for (const Triangle& t : mesh.triangles) fmt::print(out, "3 {} {} {}\n", t[0], t[1], t[2]);
    return;
  }
  std::string bytes;
  for (const Vec3& p : mesh.vertices)
    for (int k = 0; k < 3; ++k) io::storeLittle(bytes, p[k]);
  for (const Triangle& t : mesh.triangles) {
    io::storeLittle(bytes, std::uint8_t{3});
    for (Index v : t) io::storeLittle(bytes, static_cast<std::uint32_t>(v));
  }
  out << bytes;
}

}  // namespace

void checkSurfaceOutput(const std::filesystem::path& path) {
  if (!isSurfaceFile(path))
    throw Error(fmt::format("{}: unknown surface format '{}' (use .obj, .off, .stl or .ply)", path.string(),
                            io::lowerExtension(path)));
}

void writeSurface(const std::filesystem::path& path, const TriMesh& mesh, const SurfaceWriteOptions& options) {
  const std::string ext = io::lowerExtension(path);
  checkSurfaceOutput(path);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (Index v : mesh.triangles[t])
      if (v >= mesh.vertices.size())
        throw Error(
            fmt::format("{}: triangle {} refers to vertex {} of {}", path.string(), t, v, mesh.vertices.size()));
  AtomicFile file(path);
  std::ostream& out = file.stream();
  if (ext == ".obj") writeObj(out, mesh);
  if (ext == ".off") writeOff(out, mesh);
  if (ext == ".stl") writeStl(out, mesh, options.binary);
  if (ext == ".ply") writePly(out, mesh, options.binary);
  file.commit();
}

}  // namespace vrd
