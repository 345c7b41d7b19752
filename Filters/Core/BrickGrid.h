// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BrickGrid.h
 * @brief A volume as disjoint bricks of points, their value ranges, and which
 * of them are resident within a byte budget (no VTK, no GL).
 *
 * The one brick concept of the project: the GPU core keeps only the bricks an
 * isovalue crosses when a volume is over one 3D texture or the GPU budget, the
 * page streams bricks, and BlockLOD's blocks nest inside them. It is plain
 * index and byte work:
 *
 * 1. **Partition.** BrickGrid cuts the point lattice (nx x ny x nz, x fastest)
 *    into bricks of `brickPoints` points a side; brick b along an axis owns
 *    the points [b B, min((b + 1) B, n) - 1], so the last brick of an axis may
 *    be smaller. Bricks are **disjoint**: every point is owned by exactly one
 *    brick, which is what is sent or stored once. B is a multiple of 8
 *    (BlockCells), so a brick's first point is a BlockLOD block's first point
 *    and a brick holds whole blocks (but the last).
 * 2. **What a brick's cells read.** A brick draws the cells whose first
 *    corner it owns; their far corners are the owned points shifted by one,
 *    so the points those cells read are the owned extent grown by 1 on the +
 *    side, and gradients by central differences read `apron` (1) more on
 *    each side: ReadPoints(), clamped to the volume. The bricks that must be
 *    present before a brick's cells can be drawn are
 *    BricksTouching(ReadPoints(brick, apron)): itself and up to 26 neighbours
 *    (7 when the apron is 0).
 * 3. **Ranges.** ComputeBrickRanges() takes, for every brick, the least and
 *    greatest value over its read points. A cell crosses an isovalue iso when
 *    min < iso <= max over its corners (the convention of the GPU pyramid
 *    and BlockLOD); its corners are among the brick's read points, so a brick
 *    whose range does not hold iso that way has no crossing cell: skipping it
 *    changes no count (the argument of VolumeTiles.h, one level up).
 *    ActiveBricks() lists the bricks some isovalue crosses.
 * 4. **Bytes.** CopyBrick() cuts any extent (a brick's owned or read points)
 *    out of the dense volume; WriteBrick() puts a brick's owned points back
 *    into it, so a host assembles the volume from bricks as they arrive.
 * 5. **Residency.** BrickResidency tracks which bricks are resident and
 *    evicts the least recently used ones to keep their bytes within a budget.
 *
 * Values are handled as bytes (`bytesPerValue`), so every scalar type keeps
 * its representation; only the ranges read values, through ScalarType.
 *
 * @sa VolumeTiles.h (the same range argument for the pyramid's level-1 tiles),
 * BlockLOD.h (the blocks bricks align with), HistoPyramidGL.h.
 */
#ifndef MedicalIsosurfaces_BrickGrid_h
#define MedicalIsosurfaces_BrickGrid_h

#include "BlockLOD.h"
#include "ScalarTypes.h"

#include <cstdint>
#include <list>
#include <unordered_map>
#include <vector>

namespace mediso
{

/// Disjoint bricks of a point lattice and the extents they own and read.
class BrickGrid
{
public:
  BrickGrid() = default;
  /**
   * Bricks of `brickPoints` points a side over `points` (x, y, z; each at
   * least 1). `brickPoints` must be a positive multiple of BlockCells (8);
   * otherwise, or for a lattice with an empty axis, the grid is invalid
   * (IsValid() false, no bricks).
   */
  BrickGrid(const int points[3], int brickPoints);

  bool IsValid() const { return this->BrickPoints > 0; }
  /// Points per axis of the whole lattice.
  const int* GetPoints() const { return this->Points; }
  /// Points a brick owns along each axis (the last brick of an axis may own fewer).
  int GetBrickPoints() const { return this->BrickPoints; }
  /// Bricks along x, y, z (0 for an invalid grid).
  const int* GetBricksPerAxis() const { return this->Bricks; }
  /// Bricks in all; brick id = bx + nx (by + ny bz).
  std::int64_t GetNumberOfBricks() const;

  /// The id of brick (bx, by, bz), and back.
  std::int64_t BrickId(int bx, int by, int bz) const;
  void BrickIndex(std::int64_t brick, int index[3]) const;

  /**
   * The inclusive point extent [x0, x1, y0, y1, z0, z1] that `brick` owns:
   * what travels when it is sent. An id outside the grid gives an empty
   * extent (x0 > x1).
   */
  void OwnedPoints(std::int64_t brick, int extent[6]) const;

  /**
   * The points the brick's cells read: the owned extent grown by 1 point on
   * the + side (the far corners of the cells whose first corner it owns) and
   * by `apron` (>= 0) more points on each side (1 for gradients by central
   * differences), clamped to the volume.
   */
  void ReadPoints(std::int64_t brick, int apron, int extent[6]) const;

  /**
   * The ids of the bricks that own a point of `extent` (inclusive, clamped
   * to the volume), x fastest, increasing; empty for an empty extent.
   */
  std::vector<std::int64_t> BricksTouching(const int extent[6]) const;

  /// Bytes of the brick's owned points at `bytesPerValue` bytes a value.
  std::uint64_t OwnedBytes(std::int64_t brick, int bytesPerValue) const;

  /// Points in an inclusive extent (0 when it is empty).
  static std::uint64_t ExtentPoints(const int extent[6]);

private:
  int Points[3] = { 0, 0, 0 };
  int BrickPoints = 0;
  int Bricks[3] = { 0, 0, 0 };
};

/// The least and greatest value a brick's cells read; Min > Max when it reads no number.
struct BrickRange
{
  double Min;
  double Max;
};

/**
 * Per brick of `grid`, the least and greatest value of `data` (`type`, the
 * grid's points, x fastest) over ReadPoints(brick, apron). NaN values are
 * left out; a brick that reads only NaN gets Min > Max, which no isovalue
 * lies between. Empty for an invalid grid or null data.
 */
std::vector<BrickRange> ComputeBrickRanges(
  const BrickGrid& grid, ScalarType type, const void* data, int apron, const ParallelFor& parallel);

/// Whether some isovalue iso (NaN ones left out) has range.Min < iso <= range.Max.
bool BrickCrosses(const BrickRange& range, const std::vector<double>& isovalues);

/// The ids of the bricks some isovalue crosses (BrickCrosses), increasing.
std::vector<std::int64_t> ActiveBricks(
  const std::vector<BrickRange>& ranges, const std::vector<double>& isovalues);

/**
 * Copies the points of `extent` (inclusive; typically OwnedPoints(brick) or
 * ReadPoints(brick, apron)) out of the dense `volume` into `out`, x fastest,
 * as ExtentPoints(extent) values of `bytesPerValue` bytes. Returns false and
 * writes nothing when the brick id or the extent is not inside the grid.
 */
bool CopyBrick(const BrickGrid& grid, std::int64_t brick, const int extent[6], const void* volume,
  int bytesPerValue, void* out);

/**
 * Writes the points `brick` owns into the dense `volume`, taking them from
 * `brickValues`, which holds the points of `extent` (x fastest; an extent that
 * contains OwnedPoints(brick): the owned points themselves, as sent, or a
 * copy with its apron). Returns false and writes nothing when `extent` does
 * not contain the owned points or lies outside the grid.
 */
bool WriteBrick(const BrickGrid& grid, std::int64_t brick, const int extent[6], int bytesPerValue,
  const void* brickValues, void* volume);

/**
 * Which bricks are resident, and their least recently used order, within a
 * byte budget. A host calls Touch() for every brick it uses in a frame and
 * MakeResident() for a brick it is about to store; the bricks that must make
 * room are handed back for the host to free.
 */
class BrickResidency
{
public:
  /// The byte budget (default: no limit). Lowering it evicts nothing until the next MakeResident().
  void SetBudget(std::uint64_t bytes) { this->Budget = bytes; }
  std::uint64_t GetBudget() const { return this->Budget; }

  bool IsResident(std::int64_t brick) const;
  /// Marks a resident brick as the most recently used (nothing for another id).
  void Touch(std::int64_t brick);

  /**
   * Records `brick` (of `bytes` bytes) as resident and most recently used,
   * first evicting least recently used bricks (appended to `evicted`, oldest
   * first) until the resident bytes fit the budget. False, with nothing
   * evicted, when the brick alone is over the budget. A brick already
   * resident is touched, and its bytes updated.
   */
  bool MakeResident(std::int64_t brick, std::uint64_t bytes, std::vector<std::int64_t>& evicted);

  /// Forgets one brick (freed by the host); false when it was not resident.
  bool Evict(std::int64_t brick);
  /// Forgets every brick.
  void Clear();

  std::uint64_t GetResidentBytes() const { return this->ResidentBytes; }
  std::size_t GetNumberOfResidentBricks() const { return this->Order.size(); }
  /// Resident bricks, least recently used first.
  std::vector<std::int64_t> GetResidentBricks() const;

private:
  struct Entry
  {
    std::int64_t Brick;
    std::uint64_t Bytes;
  };
  std::uint64_t Budget = ~std::uint64_t(0);
  std::uint64_t ResidentBytes = 0;
  std::list<Entry> Order; // least recently used first
  std::unordered_map<std::int64_t, std::list<Entry>::iterator> Where;
};

} // namespace mediso

#endif
