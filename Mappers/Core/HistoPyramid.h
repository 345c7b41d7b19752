// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file HistoPyramid.h
 * @brief CPU reference of the HistoPyramid used by the GPU isosurface mapper (no VTK).
 *
 * Cell rasterisation (Liu, Clapworthy & Dong 2009, as used by "Hardware
 * Accelerated Medical Data Visualisation on the Web", section 4.1) draws every
 * active cell of a volume as one primitive. A HistoPyramid (Ziegler et al.
 * 2006) finds them on the GPU without any per-cell CPU work: the base level
 * holds, per cell, the number of primitives it emits, every level above holds
 * the sums of its children, and primitive number k is found by walking down
 * from the top, choosing at each node the child whose running sum covers k.
 *
 * This file is the CPU model of the exact layout and traversal the GLSL
 * implements, so that the GPU pyramid can be checked against it number for
 * number, and so that the design is tested on its own:
 *
 * - 3D, 8:1, with the sizes of PyramidLayout (level 0 the cell grid padded
 *   to powers of two, each level above halving every axis longer than 1).
 *   A 3D pyramid keeps space in the hierarchy (a node is a box of cells),
 *   which is what makes front-to-back order cheap. The GPU stores the same
 *   counts packed into 2D atlases (see PyramidLayout and HistoPyramidGL);
 *   this model stores them plainly, one count per node.
 * - Base counts. With several isovalues in one pass, a cell emits one
 *   primitive per isovalue whose surface crosses it (min < iso <= max over
 *   its 8 corners, the convention of vtkMarchingCubes and vtkBlockLODContour),
 *   so a base value is 0..number of isovalues, and the r-th primitive of a
 *   cell is its r-th crossing isovalue in increasing isovalue order.
 * - Front-to-back order from the traversal. At every node the 8 children are
 *   visited nearest first: along each axis, the near half is the one on the
 *   eye's side of the node's split plane. With this order, for any eye
 *   position (perspective or, with the eye far away, parallel projection),
 *   the primitives come out so that a cell never precedes a cell that is in
 *   front of it along a ray from the eye: early-z culling works without any
 *   per-frame sort (the paper sorted on the CPU).
 */
#ifndef MedicalIsosurfaces_HistoPyramid_h
#define MedicalIsosurfaces_HistoPyramid_h

#include "PyramidLayout.h"

#include <cstdint>
#include <vector>

namespace mediso
{

class HistoPyramid
{
public:
  /// Builds the pyramid over a grid of `cells` (x, y, z) whose base counts
  /// are given x fastest (one count per cell).
  void Build(const int cells[3], const std::vector<std::uint32_t>& baseCounts);

  /// Base counts of a scalar volume (x fastest, `points` per axis) for a set
  /// of isovalues: the number of isovalues whose surface crosses each cell.
  template <typename T>
  static std::vector<std::uint32_t> CountCrossings(
    const T* data, const int points[3], const std::vector<double>& isovalues);

  /// Total number of primitives (the value of the top node).
  std::uint64_t GetTotal() const;

  /// Number of levels, base (0) to top.
  int GetNumberOfLevels() const { return this->Layout.GetNumberOfLevels(); }

  /// Size of a level (nodes per axis).
  const int* GetLevelSize(int level) const { return this->Layout.Size(level).data(); }

  /// The layout the levels follow.
  const PyramidLayout& GetLayout() const { return this->Layout; }

  /// Count stored at a node of a level.
  std::uint32_t GetCount(int level, int i, int j, int k) const;

  /// Primitive `index` (0 <= index < GetTotal()) in front-to-back order for an
  /// eye at `eye` (in cell units: cell (i, j, k) spans [i, i+1] x [j, j+1] x
  /// [k, k+1]). Returns the cell and, in `rank`, which of the cell's
  /// primitives it is (0 .. base count - 1).
  void Traverse(std::uint64_t index, const double eye[3], int cell[3], int& rank) const;

private:
  PyramidLayout Layout;
  std::vector<std::vector<std::uint32_t>> Counts; // per level, x fastest
};

} // namespace mediso

#endif
