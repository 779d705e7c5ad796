// Meshes from Python: tet and triangle meshes as NumPy arrays, reading, checking, tetrahedralising.

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <limits>

#include "bindings.h"
#include "vrdeform/error.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/io/tet_io.h"
#include "vrdeform/io/tetrahedralise.h"
#include "vrdeform/mesh/surface_check.h"
#include "vrdeform/mesh/tet_mesh.h"

namespace py = pybind11;

namespace vrd::python {
namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using IndexArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

std::vector<Vec3> vertexRows(const FloatArray& a) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw Error("vertices: an array of shape (n, 3)");
  std::vector<Vec3> out(std::size_t(a.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec3(a.at(i, 0), a.at(i, 1), a.at(i, 2));
  return out;
}

// Rows of N vertex indices, each within [0, vertices); the meshes' own checks do the rest.
template <std::size_t N>
std::vector<std::array<Index, N>> indexRows(const IndexArray& a, std::size_t vertices, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != py::ssize_t(N)) throw Error(fmt::format("{}: an array of shape (n, {})", what, N));
  std::vector<std::array<Index, N>> out(std::size_t(a.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i)
    for (std::size_t k = 0; k < N; ++k) {
      const std::int64_t v = a.at(i, k);
      if (v < 0 || std::uint64_t(v) >= vertices)
        throw Error(fmt::format("{}: row {} refers to vertex {}, but there are {} vertices", what, i, v, vertices));
      out[i][k] = Index(v);
    }
  return out;
}

py::array_t<float> vertexArray(const std::vector<Vec3>& v) {
  py::array_t<float> out({py::ssize_t(v.size()), py::ssize_t(3)});
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k) out.mutable_at(i, k) = v[i][k];
  return out;
}

template <std::size_t N>
py::array_t<std::int64_t> indexArray(const std::vector<std::array<Index, N>>& rows) {
  py::array_t<std::int64_t> out({py::ssize_t(rows.size()), py::ssize_t(N)});
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t k = 0; k < N; ++k) out.mutable_at(i, k) = rows[i][k];
  return out;
}

}  // namespace

void bindMesh(py::module_& m) {
  py::class_<TetMesh>(m, "TetMesh", "A tet mesh: vertices (n, 3) float32 and tets (m, 4) vertex indices")
      .def(py::init([](const FloatArray& vertices, const IndexArray& tets) {
             TetMesh mesh{vertexRows(vertices), {}};
             mesh.tets = indexRows<4>(tets, mesh.vertices.size(), "tets");
             validateTetMesh(mesh);
             return mesh;
           }),
           py::arg("vertices"), py::arg("tets"))
      .def_property_readonly(
          "vertices", [](const TetMesh& mesh) { return vertexArray(mesh.vertices); }, "a copy")
      .def_property_readonly(
          "tets", [](const TetMesh& mesh) { return indexArray(mesh.tets); }, "a copy")
      .def("__repr__", [](const TetMesh& mesh) {
        return fmt::format("TetMesh({} vertices, {} tets)", mesh.vertices.size(), mesh.tets.size());
      });
  py::class_<TriMesh>(m, "TriMesh", "A triangle mesh: vertices (n, 3) float32 and triangles (m, 3) vertex indices")
      .def(py::init([](const FloatArray& vertices, const IndexArray& triangles) {
             TriMesh mesh{vertexRows(vertices), {}};
             mesh.triangles = indexRows<3>(triangles, mesh.vertices.size(), "triangles");
             validateTriMesh(mesh);
             return mesh;
           }),
           py::arg("vertices"), py::arg("triangles"))
      .def_property_readonly(
          "vertices", [](const TriMesh& mesh) { return vertexArray(mesh.vertices); }, "a copy")
      .def_property_readonly(
          "triangles", [](const TriMesh& mesh) { return indexArray(mesh.triangles); }, "a copy")
      .def("__repr__", [](const TriMesh& mesh) {
        return fmt::format("TriMesh({} vertices, {} triangles)", mesh.vertices.size(), mesh.triangles.size());
      });

  m.def(
      "read_tet_mesh", [](const std::filesystem::path& path) { return readTetMesh(path); }, py::arg("path"),
      "Reads a tet mesh (.msh, .mesh, .vtk, .vtu, .node/.ele)");
  m.def(
      "write_tet_mesh", [](const std::filesystem::path& path, const TetMesh& mesh) { writeTetMesh(path, mesh); },
      py::arg("path"), py::arg("mesh"), "Writes a tet mesh; the format follows the file's extension");
  m.def("read_surface", &readSurface, py::arg("path"), "Reads a triangle surface (.obj, .stl, .ply, .off)");
  m.def(
      "check_surface",
      [](const TriMesh& mesh, bool closed) {
        SurfaceCheckOptions options;
        options.requireClosed = closed;
        const SurfaceReport r = checkSurface(mesh, options);
        py::list issues;
        for (const SurfaceIssue& i : r.issues) issues.append(i.message);
        py::dict d;
        d["ok"] = r.ok();
        d["issues"] = issues;
        d["components"] = r.components;
        d["area"] = r.area;
        d["volume"] = r.volume;
        d["summary"] = r.summary();
        return d;
      },
      py::arg("mesh"), py::arg("closed") = true,
      "What `vrdeform mesh check` finds: ok, issues (messages), components, area, volume, summary");
  m.def(
      "tetrahedralise",
      [](const TriMesh& surface, std::size_t tets, const std::string& mesher, double maxVolume) {
        TetrahedraliseOptions options;
        if (mesher == "tetgen")
          options.mesher = Mesher::TetGen;
        else if (mesher != "builtin")
          throw Error(fmt::format("mesher '{}': builtin or tetgen", mesher));
        options.targetTets = tets;
        options.maxVolume = maxVolume;
        options.stop = ctrlC();
        try {
          py::gil_scoped_release release;
          return tetrahedralise(surface, options).mesh;
        } catch (const Stopped&) {
          if (PyErr_Occurred()) throw py::error_already_set();  // the KeyboardInterrupt
          throw;
        }
      },
      py::arg("surface"), py::arg("tets") = 0, py::arg("mesher") = "builtin", py::arg("max_volume") = 0.0,
      "Checks a closed surface and fills it with tets (about `tets` of them when given); Ctrl-C stops it between the "
      "mesher's runs");
}

}  // namespace vrd::python
