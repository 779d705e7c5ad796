#include "vrdeform/io/tet_io.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <limits>

#include "io/extension.h"
#include "io/tet_formats.h"
#include "vrdeform/core/atomic_file.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

[[noreturn]] void unknownFormat(const std::filesystem::path& path) {
  throw Error(fmt::format("{}: unknown tet mesh format '{}' (expected .node, .ele, .mesh, .msh, .vtk or .vtu)",
                          path.string(), path.extension().string()));
}

}  // namespace

namespace io {

void checkReadMesh(const TetMesh& mesh, const std::string& name) {
  if (mesh.tets.empty()) throw Error(fmt::format("{}: no tetrahedra in the file", name));
  if (mesh.vertices.size() >= std::numeric_limits<Index>::max())
    throw Error(fmt::format("{}: {} vertices are more than this library can index", name, mesh.vertices.size()));
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (!isFinite(mesh.vertices[v]))
      throw Error(fmt::format("{}: vertex {} has a non-finite or out-of-range coordinate ({}, {}, {})", name, v + 1,
                              mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z()));
}

void checkWritableMesh(const TetMesh& mesh) {
  if (mesh.tets.empty()) throw Error("cannot write a tet mesh without tetrahedra");
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (!isFinite(mesh.vertices[v])) throw Error(fmt::format("cannot write vertex {}: non-finite coordinate", v + 1));
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (Index i : mesh.tets[t])
      if (i >= mesh.vertices.size())
        throw Error(fmt::format("cannot write tet {}: it refers to vertex {}, but there are only {} vertices", t + 1,
                                std::size_t(i) + 1, mesh.vertices.size()));
}

}  // namespace io

TetMesh readTetMesh(const std::filesystem::path& path, std::vector<Triangle>* faces) {
  if (faces) faces->clear();
  const std::string ext = io::lowerExtension(path);
  if (ext == ".node" || ext == ".ele") return io::readTetGen(path, faces);
  TetMesh mesh;
  const std::string name = path.string();
  if (ext == ".mesh") {
    mesh = io::readMedit(io::readFileBytes(path), name, faces);
  } else if (ext == ".msh") {
    mesh = io::readGmsh(io::readFileBytes(path), name, faces);
  } else if (ext == ".vtk") {
    mesh = io::readVtkLegacy(io::readFileBytes(path), name, faces);
  } else if (ext == ".vtu") {
    mesh = io::readVtu(io::readFileBytes(path), name, faces);
  } else {
    unknownFormat(path);
  }
  io::checkReadMesh(mesh, name);
  return mesh;
}

void checkTetMeshOutput(const std::filesystem::path& path) {
  const std::string ext = io::lowerExtension(path);
  if (!(ext == ".node" || ext == ".ele" || ext == ".mesh" || ext == ".msh" || ext == ".vtk" || ext == ".vtu"))
    unknownFormat(path);
}

void writeTetMesh(const std::filesystem::path& path, const TetMesh& mesh, const TetWriteOptions& options) {
  checkTetMeshOutput(path);
  const std::string ext = io::lowerExtension(path);
  io::checkWritableMesh(mesh);
  if (ext == ".node" || ext == ".ele") return io::writeTetGen(path, mesh);
  AtomicFile file(path);
  if (ext == ".mesh") {
    io::writeMedit(file.stream(), mesh);
  } else if (ext == ".msh") {
    io::writeGmsh(file.stream(), mesh, options.gmshVersion);
  } else if (ext == ".vtk") {
    io::writeVtkLegacy(file.stream(), mesh);
  } else {
    io::writeVtu<4>(file.stream(), mesh.vertices, mesh.tets, {}, options);
  }
  file.commit();
}

}  // namespace vrd
