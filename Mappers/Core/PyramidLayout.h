// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file PyramidLayout.h
 * @brief The layout of the 3D HistoPyramid over a cell grid, stated once (no VTK).
 *
 * The CPU model (HistoPyramid), the GPU passes (HistoPyramidGL) and the
 * drawing program's walk (IsosurfaceRendererGL) all take their sizes from
 * this class:
 *
 * - Levels. Level 0 is the cell grid padded to a power of two per axis
 *   (padding cells count 0); each level above halves every axis longer than
 *   1, down to a single node. A one-cell grid still gets a level 1 (the GPU
 *   never stores level 0 and needs a level above it). Factor(l) is the
 *   number of children of a level-l node per axis (2, or 1 along an axis
 *   that has already reached one node).
 * - Packing. A stored level (1 and up) holds 2x2 nodes (x, y) per RGBA
 *   texel: texel (i, j, k) holds node (2i + a, 2j + b, k) in component
 *   a + 2b (a node beyond an axis of one node counts 0). The 8 children of a
 *   node of the level above are then the 4 components of 2 texels.
 * - Atlas. A stored level is a 2D texture: its z-slices of packed texels are
 *   laid side by side, AtlasColumns(l) slices per row, slice k at column
 *   k % columns and row k / columns. Every size is a power of two, so the
 *   atlas has no gaps and addresses are shifts and masks. A 2D target, not
 *   a 3D texture's layers, lets each pass draw a whole level in one draw
 *   call without geometry shaders or gl_Layer (neither exists in OpenGL ES
 *   3.0 / WebGL2).
 * - Formats. Each stored level takes the narrowest unsigned integer format
 *   that holds its largest count (MaximumIsovalues isovalues crossing every
 *   cell under a node): 8 bits for level 1, 16 up to level 4, 32 above.
 * - Tiles. The level-1 pass draws only the tiles (TileTexels x TileTexels
 *   packed texels of one slice) that an isovalue can cross.
 */
#ifndef MedicalIsosurfaces_PyramidLayout_h
#define MedicalIsosurfaces_PyramidLayout_h

#include <array>
#include <cstdint>
#include <vector>

namespace mediso
{

/// Most isovalues one pyramid counts at once (and one frame draws).
constexpr int MaximumIsovalues = 8;

class PyramidLayout
{
public:
  using Int3 = std::array<int, 3>;

  /// Packed texels per side of a level-1 tile (TileTexels x TileTexels x 1 texels).
  static constexpr int TileTexels = 4;

  PyramidLayout() = default;
  /// The layout over a grid of `cells` cells per axis (each at least 1).
  explicit PyramidLayout(const int cells[3]);

  /// Real cells per axis.
  const Int3& GetCells() const { return this->Cells; }
  /// Number of levels, base (0) to top; 0 for a default-constructed layout.
  int GetNumberOfLevels() const { return static_cast<int>(this->Sizes.size()); }
  /// Nodes per axis of a level.
  const Int3& Size(int level) const { return this->Sizes[level]; }
  /// Children per axis of a node of `level` (>= 1): 1 or 2.
  Int3 Factor(int level) const;
  /// Base cells per axis under a node of `level`.
  Int3 CellsPerNode(int level) const;

  ///@{
  /// A stored level (>= 1): packed texels per axis, atlas columns, atlas size.
  Int3 Packed(int level) const;
  int AtlasColumns(int level) const { return this->Columns[level]; }
  std::array<int, 2> AtlasSize(int level) const;
  /// Bytes per node (1, 2 or 4) of a stored level's format.
  int BytesPerNode(int level) const { return this->Bytes[level]; }
  ///@}

  /// Bytes of all stored levels (levels 1 .. top).
  std::uint64_t GetStoredBytes() const;

  /// Atlas texel of packed texel (x, y, z) of a stored level.
  std::array<int, 2> AtlasTexel(int level, int x, int y, int z) const;

  /// Level-1 tiles per axis (x, y per slice; z: one per slice).
  Int3 TileCounts() const;

  bool operator==(const PyramidLayout& other) const
  {
    return this->Cells == other.Cells;
  }
  bool operator!=(const PyramidLayout& other) const { return !(*this == other); }

private:
  Int3 Cells = { { 0, 0, 0 } };
  std::vector<Int3> Sizes;
  std::vector<int> Columns; // per level (0 for level 0)
  std::vector<int> Bytes;   // per level (0 for level 0)
};

} // namespace mediso

#endif
