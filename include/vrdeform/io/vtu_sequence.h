#pragma once
// A deforming tet mesh saved for ParaView: one .vtu per frame and a .pvd collection listing them
// with their times (open the .pvd and press play).

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "vrdeform/io/tet_io.h"

namespace vrd {

class VtuSequence {
 public:
  /// Frames go beside `pvdPath` as <stem>_00000.vtu, <stem>_00001.vtu, ... An empty collection is
  /// written at once, so a folder that cannot be written fails here. `restMesh` gives the tets and
  /// the rest positions that displacements are measured from. `options`: the .vtu encoding (default:
  /// appended raw binary, as ParaView writes). Throws vrd::Error.
  VtuSequence(std::filesystem::path pvdPath, TetMesh restMesh, TetWriteOptions options = {});
  /// The same for a deforming surface (a cloth, a render mesh): its triangles are the cells.
  VtuSequence(std::filesystem::path pvdPath, TriMesh restSurface, TetWriteOptions options = {});

  /// Writes the next frame: `positions` (one per rest vertex, finite) as the points, with point data
  /// `displacement` = positions - rest; then rewrites the .pvd atomically, so it is valid after every
  /// frame. `time` must be finite and greater than the previous frame's. Throws vrd::Error.
  void addFrame(double time, std::span<const Vec3> positions);

  std::size_t frameCount() const { return frames_.size(); }
  /// The .vtu of frame `i`.
  std::filesystem::path framePath(std::size_t i) const;

 private:
  void writeCollection() const;

  struct Frame {
    double time;
    std::string file;  // relative to the .pvd
  };
  std::filesystem::path pvdPath_;
  std::vector<Vec3> restPoints_;
  std::vector<Tet> tets_;            // the cells: tets, or
  std::vector<Triangle> triangles_;  // triangles
  TetWriteOptions options_;
  std::vector<Frame> frames_;
  std::vector<Vec3> displacement_;
};

}  // namespace vrd
