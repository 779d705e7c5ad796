#include "vrdeform/io/vtu_sequence.h"

#include <fmt/format.h>

#include <cmath>

#include "io/tet_formats.h"
#include "io/text_out.h"
#include "io/xml_escape.h"
#include "vrdeform/core/atomic_file.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

std::string frameFile(const std::filesystem::path& pvdPath, std::size_t i) {
  return fmt::format("{}_{:05}.vtu", pvdPath.stem().string(), i);
}

}  // namespace

VtuSequence::VtuSequence(std::filesystem::path pvdPath, TetMesh restMesh, TetWriteOptions options)
    : pvdPath_(std::move(pvdPath)), options_(options) {
  io::checkWritableMesh(restMesh);
  restPoints_ = std::move(restMesh.vertices);
  tets_ = std::move(restMesh.tets);
  writeCollection();
}

VtuSequence::VtuSequence(std::filesystem::path pvdPath, TriMesh restSurface, TetWriteOptions options)
    : pvdPath_(std::move(pvdPath)), options_(options) {
  validateTriMesh(restSurface);
  if (restSurface.triangles.empty()) throw Error("VtuSequence: the surface has no triangles");
  restPoints_ = std::move(restSurface.vertices);
  triangles_ = std::move(restSurface.triangles);
  writeCollection();
}

std::filesystem::path VtuSequence::framePath(std::size_t i) const {
  return pvdPath_.parent_path() / frameFile(pvdPath_, i);
}

void VtuSequence::addFrame(double time, std::span<const Vec3> positions) {
  if (!std::isfinite(time)) throw Error(fmt::format("VtuSequence: frame time {} is not finite", time));
  if (!frames_.empty() && !(time > frames_.back().time))
    throw Error(fmt::format("VtuSequence: frame time {} does not come after the previous frame's {}", time,
                            frames_.back().time));
  if (positions.size() != restPoints_.size())
    throw Error(
        fmt::format("VtuSequence: {} positions for a mesh of {} vertices", positions.size(), restPoints_.size()));
  displacement_.resize(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    if (!isFinite(positions[v])) throw Error(fmt::format("VtuSequence: position {} is not finite", v));
    displacement_[v] = positions[v] - restPoints_[v];
  }
  const std::size_t index = frames_.size();
  {
    AtomicFile file(framePath(index));
    const io::VtuPointArray data[] = {{"displacement", displacement_}};
    if (triangles_.empty())
      io::writeVtu<4>(file.stream(), positions, tets_, data, options_);
    else
      io::writeVtu<3>(file.stream(), positions, triangles_, data, options_);
    file.commit();
  }
  frames_.push_back({time, frameFile(pvdPath_, index)});
  try {
    writeCollection();
  } catch (...) {
    frames_.pop_back();
    throw;
  }
}

void VtuSequence::writeCollection() const {
  AtomicFile file(pvdPath_);
  {
    io::TextOut out(file.stream());
    out.print("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
    out.print("  <Collection>\n");
    // "{}": the shortest text that reads back as the same double.
    for (const Frame& f : frames_)
      out.print("    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n", f.time, escapeXml(f.file));
    out.print("  </Collection>\n</VTKFile>\n");
  }
  file.commit();
}

}  // namespace vrd
