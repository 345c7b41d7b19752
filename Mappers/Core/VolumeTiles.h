// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file VolumeTiles.h
 * @brief What the GPU pyramid needs from a volume on the CPU: its rows as the
 * volume texture stores them, and the value range of every level-1 tile (no GL, no VTK).
 *
 * HistoPyramidGL keeps the volume as a 3D texture of 4 points to a texel
 * along x, and draws level 1 only over the tiles an isovalue can cross
 * (mediso::PyramidLayout::TileTexels texels of level 1 a side, one slice of
 * nodes deep). Both are plain data work, done once per volume:
 *
 * - PackVolumeRows() pads every row to a whole number of texels;
 * - VolumeTiles::Compute() takes, for every tile, the least and greatest
 *   value its cells read (in the type the thresholds have: int32, uint32 or
 *   float, which hold every value of the volume's type exactly);
 * - VolumeTiles::ActiveRectangles() turns, for one set of thresholds, the
 *   tiles whose range holds one into the level-1 pass's vertices: per slice
 *   and row of tiles, each run of active tiles as one rectangle.
 *
 * A tile's points are linked by cell edges, so an isovalue in its range
 * means one of its cells crosses it: skipping the other tiles changes no count.
 */
#ifndef MedicalIsosurfaces_VolumeTiles_h
#define MedicalIsosurfaces_VolumeTiles_h

#include "IsoThresholds.h"
#include "PyramidLayout.h"
#include "ScalarTypes.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace mediso
{

/// Runs body(begin, end) over sub-ranges that together cover [begin, end), possibly concurrently.
using GLParallelFor = std::function<void(
  std::int64_t, std::int64_t, const std::function<void(std::int64_t, std::int64_t)>&)>;

/// Whether every point of [first, last] (inclusive, per axis) holds its value: a volume whose
/// values arrive region by region (VolumeTiles::ComputeRegion()).
using PointsArrived = std::function<bool(const int first[3], const int last[3])>;

/// The parallel-for to use: `parallel`, or one that runs the whole range at once when it is empty.
GLParallelFor SerialIfEmpty(const GLParallelFor& parallel);

/// Texels per row of the stored volume: 4 points to a texel along x.
int PackedVolumeWidth(int pointsX);

/**
 * The volume as its texture stores it: texel (i, j, k) holds points
 * (4 i + c, j, k) in component c, and where a row's points run out, its last
 * texel repeats the row's last point (so a read past the end of a row gives
 * the value a clamp to the volume would). Rows are copied as bytes, so the
 * values keep their type. Readers: pointQuad() and pointValue() in
 * HistoPyramidCommon.glsl.
 */
std::vector<unsigned char> PackVolumeRows(
  const void* data, const int points[3], int bytesPerValue, const GLParallelFor& parallel);

/**
 * PackVolumeRows() of the box `extent` (inclusive point indices per axis,
 * inside the volume) of a volume of `volumePoints` points, into `packed`
 * (resized; storage it already has is reused, so that a caller packing one
 * brick after another allocates once): a brick's texture is cut out of the
 * host's volume and padded in one copy instead of two. Both hand `parallel`
 * tasks of whole rows of at least VolumeTiles::MinimumPointsPerTask points.
 */
void PackVolumeBox(const void* volume, const int volumePoints[3], const int extent[6],
  int bytesPerValue, const GLParallelFor& parallel, std::vector<unsigned char>& packed);

/// The value range of every level-1 tile of a volume, and the active ones' rectangles.
class VolumeTiles
{
public:
  /**
   * The ranges of `data` (`type`, x fastest, `points` per axis; Float64 is
   * read as the float data it becomes on the GPU, so pass it converted) on
   * `layout`'s tiles. An empty tile (padding cells only, or only NaN values)
   * gets least > greatest, which no threshold lies between; NaN values are
   * left out (a cell with a NaN corner counts nothing anyway). `parallel`
   * gets tasks of whole slices of tiles of at least MinimumPointsPerTask
   * points.
   */
  void Compute(ScalarType type, const void* data, const int points[3], const PyramidLayout& layout,
    const GLParallelFor& parallel);
  /// Compute() of values whose rows hold `rowValues` (>= points[0]) values each, of which the
  /// first points[0] are the row's (PackVolumeRows()' rows: the texture's own copy).
  void Compute(ScalarType type, const void* data, const int points[3], int rowValues,
    const PyramidLayout& layout, const GLParallelFor& parallel);

  void Clear();

  ///@{
  /**
   * Tiles whose values arrive later: Reset() makes every tile of `layout`
   * empty for data of `type`, so that a build draws no tile.
   *
   * A volume whose values arrive region by region (a streamed one):
   * ComputeRegion() gives the tiles whose points meet [first, last]
   * (inclusive, per axis) their range again from `data` (of the volume's
   * own type: Float64 values are taken as the floats they become), each where
   * `arrived` says every point its cells read holds its value, and leaves
   * the others empty. A tile's cells then count exactly the dense volume's
   * once its points have arrived, and nothing before (not the values of
   * points still to come).
   *
   * A brick pool's tiles (HistoPyramidGL::AllocatePool()): Place() gives the
   * tiles [origin, origin + count) per axis the ranges of `part` (a brick's
   * tiles, computed on its own points, whose tile 0 is tile `origin` here),
   * or empties them where `part` is null or has fewer.
   */
  void Reset(ScalarType type, const PyramidLayout& layout);
  void ComputeRegion(ScalarType type, const void* data, const int points[3], const int first[3],
    const int last[3], const PointsArrived& arrived);
  void Place(const VolumeTiles* part, const int origin[3], const int count[3]);
  ///@}

  /// Tiles of the last Compute() (0 after Clear()).
  std::uint64_t GetNumberOfTiles() const;

  /**
   * The level-1 pass's vertices for `thresholds` (of the volume's value
   * kind): per slice and row of tiles, each run of tiles whose range holds a
   * threshold, as two triangles in level-1 atlas texels (x, y pairs).
   * @a tilesDrawn is the number of tiles they cover. `parallel` gets tasks
   * of whole slices of at least MinimumTilesPerTask tiles: one task (on the
   * calling thread, for a host whose parallel for runs a single task there)
   * for a volume of fewer tiles, as a brick's.
   */
  std::vector<std::uint16_t> ActiveRectangles(const IsoThresholds& thresholds,
    const GLParallelFor& parallel, std::uint64_t& tilesDrawn) const;

  /**
   * The fewest tiles one task of ActiveRectangles() scans: 2^16. A tile's
   * test is a few comparisons; starting and joining a thread costs about as
   * much as tens of thousands of them (more on a loaded machine), and a
   * brick of 120 points a side has 4096 tiles, scanned once per brick at
   * every isovalue change of a bricked volume.
   */
  static constexpr std::size_t MinimumTilesPerTask = std::size_t(1) << 16;

  /**
   * The fewest points one task of Compute() (its slices of tiles) and of
   * PackVolumeBox() / PackVolumeRows() (their rows) takes: 2^18, about as
   * much copying or comparing as a thread's start and join costs. A brick
   * of 56 points (59 a side with its apron, 205379 points) is one task, one
   * of 120 (123 a side) eight; a 512^3 volume has 512.
   */
  static constexpr std::size_t MinimumPointsPerTask = std::size_t(1) << 18;

  /// Whether tile t's range holds a threshold (t = x + tiles.x (y + tiles.y z)).
  bool IsActive(const IsoThresholds& thresholds, std::size_t t) const;

private:
  PyramidLayout Layout;
  std::vector<std::int32_t> IntRanges; // least, greatest per tile, by the value kind
  std::vector<std::uint32_t> UIntRanges;
  std::vector<float> FloatRanges;
};

} // namespace mediso

#endif
