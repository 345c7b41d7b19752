// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BlockLOD.h
 * @brief Block-based, level-of-detail marching cubes (no VTK).
 *
 * The CPU isosurface method of "Hardware Accelerated Medical Data
 * Visualisation on the Web" (section 4.2), in the form used by
 * vtkBlockLODContour:
 *
 * - The volume (nx x ny x nz points) is split into blocks of 8 x 8 x 8 cells.
 *   Block b along an axis covers the points [8b, min(8b + 8, n - 1)], so
 *   neighbouring blocks share a face of points. BlockRanges holds every
 *   block's minimum and maximum, computed once per input.
 * - Level of detail L in 0..3 samples the volume with a stride s = 8 >> L
 *   (cube edges of 8, 4, 2, 1 voxels; level 3 is full resolution). The samples
 *   of a level are the points whose index is a multiple of s, plus the last
 *   point n - 1 of each axis (so the last cube of an axis may be shorter and
 *   the whole volume is covered). Block faces are multiples of 8, hence of s:
 *   neighbouring blocks see the same samples on their shared face.
 * - For an isovalue only the blocks with min < iso <= max are visited (a cube
 *   is cut when some corner value >= iso and some corner < iso, the
 *   convention of vtkMarchingCubes); no cut cube lies outside them.
 * - Points live on the cut edges of the sample grid. Each edge belongs to
 *   exactly one block (the one holding its lower end, faces going to the
 *   block above them, except on the volume's last face), and that block is
 *   always visited, because it holds both ends of the edge. Pass 1 classifies
 *   a block's samples into one bit mask per row of samples, from which the
 *   cut edges of a row are a few bit operations and the cases of a row's
 *   cubes one 8 x 8 bit transpose; it marks each block's cut edges and cut
 *   cubes in bit masks and counts triangles; a prefix sum over
 *   the visited blocks gives every block its first point and first triangle;
 *   the output is allocated once; pass 2 writes the points of owned edges in
 *   bit order and the triangles of every cut cube, finding a point's id as
 *   "first point of the owner block + rank of the edge's bit". Points on
 *   shared edges are therefore merged within and across blocks, at every
 *   level: the surface is watertight (no duplicate points, no cracks).
 * - Triangles come from the marching-cubes case table the caller passes
 *   (vtkBlockLODContour passes VTK's vtkMarchingCubesTriangleCases, so this
 *   file holds no table). Points are interpolated on the edge exactly as in
 *   vtkMarchingCubes; normals are the normalised negative gradient of the
 *   original data by central differences over the level's stride (one-sided
 *   on the boundary, divided by the spacing), interpolated along the edge; at
 *   level 3 this is vtkMarchingCubes' gradient. A flat gradient falls back
 *   to the edge direction, so no normal is zero.
 * - Degenerate triangles: like vtkFlyingEdges3D, a point is created per cut
 *   edge and every triangle of the case table is kept; a triangle can only
 *   have coincident vertices when a sample value equals the isovalue exactly.
 * - Missing samples (NaN or infinite): an edge with a missing end is never cut
 *   and a cube with a missing corner makes no triangle, so such regions leave
 *   holes but never non-finite points; a normal whose gradient reads a missing
 *   sample falls back to the edge direction.
 *
 * Every pass runs over ranges of blocks through a caller-supplied ParallelFor
 * (vtkBlockLODContour passes vtkSMPTools), so the core is testable alone.
 */
#ifndef MedicalIsosurfaces_BlockLOD_h
#define MedicalIsosurfaces_BlockLOD_h

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

namespace mediso
{

/// Cells along a block edge.
constexpr int BlockCells = 8;
/// Number of levels of detail (0 coarsest .. 3 full resolution).
constexpr int NumberOfLevels = 4;

/// Sample stride (in voxels) of a level of detail.
constexpr int LevelStride(int level)
{
  return BlockCells >> level;
}

/// An (isovalue, level) pair: what the estimator and the surface cache key on.
struct SurfaceKey
{
  double Isovalue = 0;
  int Level = 0;
  bool operator==(const SurfaceKey& o) const
  {
    return this->Isovalue == o.Isovalue && this->Level == o.Level;
  }
  bool operator<(const SurfaceKey& o) const
  {
    return this->Isovalue < o.Isovalue || (this->Isovalue == o.Isovalue && this->Level < o.Level);
  }
};

/// Runs body(begin, end) over sub-ranges that together cover [begin, end),
/// possibly concurrently.
using RangeBody = std::function<void(std::int64_t, std::int64_t)>;
using ParallelFor = std::function<void(std::int64_t, std::int64_t, const RangeBody&)>;

/// A ParallelFor that runs everything on the calling thread.
void SerialFor(std::int64_t begin, std::int64_t end, const RangeBody& body);

/// Marching-cubes triangle table: 256 cases, each up to 5 triangles given as
/// edge triples and terminated by -1 (the layout of vtkMarchingCubesTriangleCases;
/// edges and corners numbered as in vtkMarchingCubes).
using TriangleCaseTable = const int (*)[16];

/// A scalar volume, x fastest, contiguous, with its placement in space.
template <typename T>
struct Volume
{
  const T* Data = nullptr;
  int Dims[3] = { 0, 0, 0 };      ///< Points along x, y, z.
  double Origin[3] = { 0, 0, 0 }; ///< World position of point (0, 0, 0).
  double Spacing[3] = { 1, 1, 1 };
  /// For a coarse copy of a volume (see MakeCoarseCopy): sample c along an
  /// axis stands for point min(SampleFirst + c * SampleStride, FullDims - 1)
  /// of the full volume, whose Origin and Spacing these are. 1 for a full volume.
  int SampleStride = 1;
  int SampleFirst[3] = { 0, 0, 0 };
  int FullDims[3] = { 0, 0, 0 };
  /// Full-volume index of sample c along an axis.
  int FullIndex(int axis, int c) const
  {
    return this->SampleStride == 1
      ? c
      : std::min(this->SampleFirst[axis] + c * this->SampleStride, this->FullDims[axis] - 1);
  }
  /// Where a parallel piece lies in the whole volume, in this volume's own
  /// samples: the whole grid's index of sample 0, and the whole grid's sample
  /// counts. GlobalDims of zero (the default) means the volume is the whole.
  /// Pieces sample coarse levels on the whole grid (MakeCoarseCopy) and number
  /// blocks in "BlockIds" on it, so they join like one volume.
  int GlobalOffset[3] = { 0, 0, 0 };
  int GlobalDims[3] = { 0, 0, 0 };
  bool IsPiece() const { return this->GlobalDims[0] > 0; }
  /// Cells (by lower corner index) whose cubes make triangles: {x0, x1, y0,
  /// y1, z0, z1}, inclusive. A parallel piece passes the range without its
  /// ghost layers, so pieces join without duplicate triangles while their
  /// normals still see the neighbour's data. Default: every cell.
  int OwnedCells[6] = { 0, 1 << 30, 0, 1 << 30, 0, 1 << 30 };
  bool HasGhostCells() const
  {
    for (int a = 0; a < 3; ++a)
    {
      if (this->OwnedCells[2 * a] > 0 || this->OwnedCells[2 * a + 1] < this->Dims[a] - 2)
      {
        return true;
      }
    }
    return false;
  }
};

/// Per-block value ranges of a volume (computed once, reused for every isovalue).
struct BlockRanges
{
  int Dims[3] = { 0, 0, 0 };
  int Blocks[3] = { 0, 0, 0 };
  std::vector<double> Min; ///< Minimum of each block's finite samples (x fastest).
  std::vector<double> Max;
  /// NaN and infinite samples (those on block faces counted once per block:
  /// exact when 0).
  std::int64_t NaNCount = 0;
  std::int64_t InfiniteCount = 0;
  double ValueRange[2] = { 0, 0 }; ///< Of the finite samples; empty (min > max) when none.

  bool HasFiniteValues() const { return this->ValueRange[0] <= this->ValueRange[1]; }

  std::int64_t GetNumberOfBlocks() const
  {
    return static_cast<std::int64_t>(this->Blocks[0]) * this->Blocks[1] * this->Blocks[2];
  }
  /// True for a block that can hold a cut cube of this isovalue.
  bool IsActive(std::int64_t block, double isovalue) const
  {
    return this->Min[block] < isovalue && isovalue <= this->Max[block];
  }
};

/// The samples of a level of detail as a volume of their own: the points whose
/// index is a multiple of LevelStride(level), plus the last point of each axis.
/// For a piece (Volume::IsPiece) the index is the whole volume's and the last
/// point is the whole volume's: every piece samples the same global grid, so
/// coarse cubes of neighbouring pieces coincide. A piece then needs ghost
/// layers of 2 * stride - 1 points for its owned cubes and their normals to be
/// exactly those of one process (see vtkBlockLODContour::RequestUpdateExtent).
/// Marching cubes at stride 1 on it gives exactly the level's surface, but
/// reads a small contiguous array instead of scattered samples of the full one
/// (1/512, 1/64, 1/8 of the data for levels 0, 1, 2). `storage` receives the
/// values; the returned volume points into it.
template <typename T>
Volume<T> MakeCoarseCopy(const Volume<T>& full, int level, std::vector<T>& storage,
  const ParallelFor& parallel);

/// MakeCoarseCopy's samples at any stride, a power of two (1 returns a copy
/// of the volume): every stride-th point and the last of each axis. The GPU
/// path's volume level -1 (stride 16, IsosurfaceScene::CoarsestLevel) samples
/// the volume this way, coarser than any Block LOD level.
template <typename T>
Volume<T> MakeStrideCopy(const Volume<T>& full, int stride, std::vector<T>& storage,
  const ParallelFor& parallel);

/// Sizes `ranges` for a volume of `dims` points with every block's range empty
/// (minimum +inf, maximum -inf), no missing sample counted and an empty value
/// range: where ComputeBlockRanges() starts, and the ranges of a streamed
/// volume before any of its values has arrived (BlockLODVolume's
/// SetStreamingVolume), taken without reading a buffer that holds nothing yet.
/// Returns the number of blocks (0 for a volume too thin to hold one cube).
std::int64_t SizeBlockRanges(const int dims[3], BlockRanges& ranges);

/// Computes BlockRanges of a volume (one read of the data, in parallel).
template <typename T>
void ComputeBlockRanges(const Volume<T>& volume, BlockRanges& ranges, const ParallelFor& parallel);

/// One block's range, as ComputeBlockRanges() takes it (its points, missing
/// samples left out), into ranges.Min/Max[block]: false, the range left as it
/// was, when the block holds no number. `nans` and `infinities` count its
/// missing samples. The values are compared in their own type: a streamed
/// volume (BlockLODVolume::RegionArrived) takes each block's range when its
/// points have arrived, and a conversion of every point to double cost that
/// pass several times the dense one's.
template <typename T>
bool ComputeBlockRange(const Volume<T>& volume, BlockRanges& ranges, std::int64_t block,
  std::int64_t& nans, std::int64_t& infinities);

/// Exact counts for one (isovalue, level), and what pass 2 needs to write it.
struct ExtractionPlan
{
  double Isovalue = 0;
  int Level = 3;       ///< Stride level of the pass on the volume it read.
  int VolumeLevel = 3; ///< Level whose volume it read (BlockLODVolume: the coarse copy below 3).
  std::vector<std::int32_t> ActiveBlocks;   ///< Linear indices of visited blocks.
  std::vector<std::int32_t> ActiveIndex;    ///< Per block: position in ActiveBlocks or -1.
  std::vector<std::int64_t> PointOffset;    ///< Per active block (+1): first point.
  std::vector<std::int64_t> TriangleOffset; ///< Per active block (+1): first triangle.
  std::vector<std::uint64_t> EdgeBits;      ///< Per active block: owned cut edges.
  std::vector<std::uint32_t> EdgeRank;      ///< Per active block and word: bits before it.
  std::vector<std::uint64_t> CutCubes;      ///< Per active block: cubes that make triangles.
  std::vector<std::uint8_t> CubeCases;      ///< Per active block: case of each cut cube.
  int WordsPerBlock = 0;
  int CubeWordsPerBlock = 0; ///< Stride of CutCubes.
  int CubesPerBlock = 0;     ///< (8 / stride)^3: stride of CubeCases.

  std::int64_t GetNumberOfPoints() const
  {
    return this->PointOffset.empty() ? 0 : this->PointOffset.back();
  }
  std::int64_t GetNumberOfTriangles() const
  {
    return this->TriangleOffset.empty() ? 0 : this->TriangleOffset.back();
  }
};

/// Bytes a plan of `level` holds for a volume of `blocks` blocks, `activeBlocks`
/// of them active (what PlanExtraction() allocates, for a check before it does).
double ExtractionPlanBytes(std::int64_t blocks, std::int64_t activeBlocks, int level);

/// Pass 1: active blocks, cut-edge masks and exact point and triangle counts.
/// `abort` (may be empty) is polled between blocks; when it returns true the
/// plan is left incomplete and false is returned.
template <typename T>
bool PlanExtraction(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  double isovalue, int level, ExtractionPlan& plan, const ParallelFor& parallel,
  const std::function<bool()>& abort = {});

/// The value range of 3-component vectors (points, normals): per component,
/// and of their length. A host can hand these to its arrays (VTK caches array
/// ranges), so that nothing downstream reads the arrays again to find them.
struct VectorRange
{
  double Min[3] = { 1e300, 1e300, 1e300 };
  double Max[3] = { -1e300, -1e300, -1e300 };
  double MinLength2 = 1e300; ///< Squared lengths.
  double MaxLength2 = -1e300;
  bool IsEmpty() const { return this->Min[0] > this->Max[0]; }
  void Add(const float v[3])
  {
    double length2 = 0;
    for (int c = 0; c < 3; ++c)
    {
      const double x = v[c];
      this->Min[c] = x < this->Min[c] ? x : this->Min[c];
      this->Max[c] = x > this->Max[c] ? x : this->Max[c];
      length2 += x * x;
    }
    this->MinLength2 = length2 < this->MinLength2 ? length2 : this->MinLength2;
    this->MaxLength2 = length2 > this->MaxLength2 ? length2 : this->MaxLength2;
  }
  void Merge(const VectorRange& o)
  {
    for (int c = 0; c < 3; ++c)
    {
      this->Min[c] = o.Min[c] < this->Min[c] ? o.Min[c] : this->Min[c];
      this->Max[c] = o.Max[c] > this->Max[c] ? o.Max[c] : this->Max[c];
    }
    this->MinLength2 = o.MinLength2 < this->MinLength2 ? o.MinLength2 : this->MinLength2;
    this->MaxLength2 = o.MaxLength2 > this->MaxLength2 ? o.MaxLength2 : this->MaxLength2;
  }
};

/// Ranges of what pass 2 wrote.
struct SurfaceRanges
{
  VectorRange Points;
  VectorRange Normals; ///< Empty without normals.
};

/// Where pass 2 writes. Arrays are sized from the plan; optional ones may be null.
template <typename IdType>
struct SurfaceBuffers
{
  float* Points = nullptr;         ///< 3 per point (world coordinates).
  float* Normals = nullptr;        ///< 3 per point, or null.
  float* Scalars = nullptr;        ///< 1 per point (the isovalue), or null.
  IdType* Connectivity = nullptr;  ///< 3 per triangle.
  std::int32_t* BlockIds = nullptr; ///< 1 per triangle (linear block index, on the whole
                                    ///< volume's grid for a piece), or null.
  IdType FirstPointId = 0;         ///< Added to every point id (several isovalues in one output).
  SurfaceRanges* Ranges = nullptr; ///< Receives the written points' and normals' ranges, or null.
};

/// Pass 2: writes the surface of a completed plan.
template <typename T, typename IdType>
void GenerateSurface(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  const ExtractionPlan& plan, const SurfaceBuffers<IdType>& out, const ParallelFor& parallel);

/**
 * @name A plan that grows (streaming)
 * For a volume whose blocks become known a few at a time (BlockLODVolume's
 * streaming), the two passes can run block by block, ahead of the frame that
 * draws the surface. BeginPlan() makes an empty plan; AppendToPlan() runs
 * pass 1 on blocks as they arrive and gives each active one its points and
 * triangles after those already in the plan (ActiveBlocks is then in the
 * order of arrival, not the volume's: GenerateSurface() needs no order);
 * GenerateBlocks() runs pass 2 on some of the plan's blocks: a block's points
 * (its owned cut edges) need only its own values, its triangles also the
 * pass 1 of the blocks above it whose edges they use (PlanOwners()). The
 * surface so made is the one Plan and Generate would make of the same
 * blocks, its points and triangles in another order.
 */
///@{
/// An empty plan of `level` for `isovalue` over a volume of `ranges`' blocks.
void BeginPlan(const BlockRanges& ranges, double isovalue, int level, ExtractionPlan& plan);
/// Pass 1 on those of `blocks` that are active for the plan's isovalue and not
/// in it yet, appended to it; returns the active index of the first appended.
template <typename T>
std::int64_t AppendToPlan(const Volume<T>& volume, const BlockRanges& ranges,
  TriangleCaseTable cases, const std::vector<std::int32_t>& blocks, ExtractionPlan& plan,
  const ParallelFor& parallel);
/// The blocks whose cut edges block `block`'s triangles may use (itself
/// excluded: the up to 7 blocks above it along one, two or three axes), into
/// `owners`; returns how many.
int PlanOwners(const BlockRanges& ranges, std::int64_t block, std::int64_t owners[7]);
/// What GenerateBlocks() writes of each block.
enum GenerateParts
{
  GeneratePoints = 1,   ///< Points (and normals, scalars) of the block's owned cut edges.
  GenerateTriangles = 2 ///< Its triangles (and block ids).
};
/// Pass 2 on the plan's active blocks `list` (active indices; every block
/// when null), writing `parts` (GenerateParts, or'd) at the blocks' offsets;
/// out.Ranges, when given, grows by what is written. A block's triangles read
/// the plan of the blocks above it as it is now: a block not in it has no cut
/// edge there.
template <typename T, typename IdType>
void GenerateBlocks(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  const ExtractionPlan& plan, const std::vector<std::int64_t>* list, int parts,
  const SurfaceBuffers<IdType>& out, const ParallelFor& parallel);
///@}

/// Sums of point and triangle counts over a list of blocks, for exact counts
/// and for the estimator's samples (BlockLODEstimator.h). With an auxiliary
/// (coarser) level, the level's counts are split by whether the block's
/// auxiliary count is positive: Points and Triangles over blocks with a
/// positive auxiliary count (every block without an auxiliary level), Rest*
/// over the others, Aux* the auxiliary level's counts over all of them.
struct BlockSums
{
  std::int64_t Blocks = 0;
  double Points = 0;
  double Triangles = 0;
  double RestPoints = 0;
  double RestTriangles = 0;
  double AuxPoints = 0;
  double AuxTriangles = 0;
};

/// Counts cut edges (points) and triangles of a level, and of `auxLevel`
/// (-1: none), on the given blocks (no allocation proportional to the output).
template <typename T>
BlockSums CountBlocks(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  const std::vector<std::int32_t>& blocks, double isovalue, int level, int auxLevel,
  const ParallelFor& parallel);

/// Linear indices of the blocks active for an isovalue, in increasing order.
std::vector<std::int32_t> ListActiveBlocks(const BlockRanges& ranges, double isovalue);

} // namespace mediso

#endif
