// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BlockLODVolume.h
 * @brief One input volume of the block LOD method, whatever its scalar type,
 * with everything kept between isovalues (no VTK).
 *
 * A host (the VTK filter vtkBlockLODContour, or a WebAssembly page) describes
 * its volume with a VolumeDescription: a pointer to contiguous values of one
 * of the ScalarType types, x fastest, and the volume's place in space and, for
 * a parallel piece, in the whole volume. BlockLODVolume then holds, until the
 * description changes:
 *
 * - the block ranges of the full volume (BlockLOD.h), computed by SetVolume();
 * - per coarse level 0-2, a contiguous copy of the level's samples and its own
 *   block ranges (MakeCoarseCopy), made the first time the level is planned
 *   (levels 0 and 1, 1/512 and 1/64 of the input, also when first counted);
 * - the active-block lists of the last few isovalues (estimates of every level
 *   use the same list).
 *
 * Plan() and Generate() run the two passes of BlockLOD.h for an (isovalue,
 * level): at level 3 on the full volume, below it at stride 1 on the level's
 * coarse copy, which gives exactly the level's surface. CountExact() and
 * CountSample() count a level exactly, or on a spread sample of active
 * blocks, for the estimator (BlockLODEstimator.h).
 *
 * Streaming (a host whose values arrive region by region, as the web page's
 * bricks do): after BeginStreaming() no block of the full volume is resident
 * and its range is empty, so no pass visits it; RegionArrived() marks points
 * as holding their values, and each block whose every read point (its own
 * points and the gradient's one more on each side) is then resident gets its
 * range from the values, once. A surface at level 3 is then exactly the
 * dense volume's wherever the blocks that can cut it are resident (their
 * neighbours included); the coarse copies read every point, so a host draws
 * levels 0-2 of a streaming volume only after EndStreaming().
 *
 * Extraction ahead (streaming): the level-3 surfaces of the isovalues a host
 * names (SetAheadIsovalues) are made block by block while the values arrive,
 * so that the frame that draws a surface once its last brick is in finds it
 * nearly made. Each RegionArrived() runs pass 1 on the blocks it completed
 * that are active for each named isovalue, appends them to that surface's
 * growing plan (BlockLOD.h, AppendToPlan) and writes their points; a block's
 * triangles are written once the blocks above it whose cut edges they use
 * are resident too. TakeAhead() writes the triangles still waiting (as a
 * Plan() would see the blocks above them now) and hands the arrays over: the
 * same points, normals and triangles as Plan() and Generate() at that moment,
 * in the order the blocks arrived. Nothing is copied at the end, and the
 * work is the dense extraction's, moved to while the transfer runs.
 *
 * The marching-cubes case table is data the host passes (BlockLOD.h,
 * TriangleCaseTable), and every pass runs through the host's ParallelFor.
 */
#ifndef MedicalIsosurfaces_BlockLODVolume_h
#define MedicalIsosurfaces_BlockLODVolume_h

#include "BlockLOD.h"
#include "ScalarTypes.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace mediso
{

/// What a host tells BlockLODVolume about its volume.
struct VolumeDescription
{
  ScalarType Type = ScalarType::Float32;
  const void* Data = nullptr; ///< Dims[0] * Dims[1] * Dims[2] values, x fastest.
  int Dims[3] = { 0, 0, 0 };
  double Origin[3] = { 0, 0, 0 }; ///< World position of the first point.
  double Spacing[3] = { 1, 1, 1 };
  /// Cells that make triangles (see Volume::OwnedCells); every cell by default.
  int OwnedCells[6] = { 0, 1 << 30, 0, 1 << 30, 0, 1 << 30 };
  /// For a parallel piece: its first point's index in the whole volume, and
  /// the whole volume's points (GlobalDims 0: the volume is the whole).
  int GlobalOffset[3] = { 0, 0, 0 };
  int GlobalDims[3] = { 0, 0, 0 };
  /// The host's stamp of the values: a change (with the same pointer) means
  /// the values changed.
  std::uint64_t Stamp = 0;

  bool IsPiece() const;
  bool operator==(const VolumeDescription& other) const;
  bool operator!=(const VolumeDescription& other) const { return !(*this == other); }
};

/// A level-3 surface extracted ahead (BlockLODVolume::TakeAhead): plain arrays.
struct SurfaceArrays
{
  std::vector<float> Points;           ///< 3 per point.
  std::vector<float> Normals;          ///< 3 per point.
  std::vector<std::int32_t> Triangles; ///< 3 point ids per triangle.
};

/// Exact or estimated size of one (isovalue, level) surface, and the cubes
/// visited to extract it (the cost model's first variable).
struct SurfaceCounts
{
  double Points = 0;
  double Triangles = 0;
  double Cubes = 0;
};

class BlockLODVolume
{
public:
  BlockLODVolume(TriangleCaseTable cases, ParallelFor parallel);
  ~BlockLODVolume();
  BlockLODVolume(const BlockLODVolume&) = delete;
  BlockLODVolume& operator=(const BlockLODVolume&) = delete;

  /// Adopts a volume. When it differs from the current one (any field of the
  /// description), forgets everything and computes the block ranges; returns
  /// true then, false when the volume is the same (or its Type is no
  /// ScalarType value: IsValid() is then false).
  bool SetVolume(const VolumeDescription& description);
  /// Adopts a volume whose values are still to arrive, streaming from the
  /// start: what SetVolume() then BeginStreaming() leave, without the block
  /// ranges SetVolume() would compute from a buffer that holds nothing yet
  /// (one read of all of it, which on the web page's 512^3 volume held its
  /// first frame, drawn from level 0). Always adopts (the values arrive
  /// anew); false only when the Type is no ScalarType value.
  bool SetStreamingVolume(const VolumeDescription& description);
  /// Forgets the volume (IsValid() turns false).
  void Reset();
  bool IsValid() const;
  const VolumeDescription& GetDescription() const { return this->Description; }
  /// Coarse copies made since SetVolume() (a host can tell one-time work).
  int GetNumberOfCoarseCopies() const;
  /// Block ranges of the full volume (value range, NaN count, per-block min/max).
  const BlockRanges& GetRanges() const { return this->Ranges; }

  /// Pass 1 for an (isovalue, level) on the level's volume (builds the
  /// level's coarse copy on first use). `abort` is polled between blocks;
  /// returns false when it stopped the pass.
  bool Plan(double isovalue, int level, ExtractionPlan& plan,
    const std::function<bool()>& abort = {});
  /// Pass 2: writes the surface of a plan made by Plan() on this volume.
  void Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int32_t>& out);
  void Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int64_t>& out);

  /// Exact counts of a plan made by Plan().
  static SurfaceCounts CountsOf(const ExtractionPlan& plan);

  /// Bytes Plan() would allocate for an (isovalue, level): the plan, and the
  /// level's coarse copy with its block ranges when it is not made yet (then
  /// the copy's active blocks are bounded by the full volume's).
  double PlanBytes(double isovalue, int level);

  /// The cost of counting one block of a level on the full volume, relative
  /// to level 0 (a block of level 3 classifies 729 samples, of level 0 eight).
  static double BlockCost(int level);
  /// What CountExact() costs, in BlockCost() units: the active blocks of the
  /// level's coarse copy where it exists (levels 0 and 1 build theirs, which
  /// are small), else the active blocks of the full volume.
  double ExactCountCost(double isovalue, int level);
  /// Exact counts of an (isovalue, level), by the route ExactCountCost() prices.
  SurfaceCounts CountExact(double isovalue, int level);
  /// Counts of `level` and `auxLevel` (-1: none) on `samples` active blocks
  /// of the full volume, one at a pseudo-random place in each of `samples`
  /// equal runs of the active list (jittered systematic sampling: the sample
  /// spreads over the volume without following its period). Every active
  /// block when `samples` is not smaller than their number.
  BlockSums CountSample(double isovalue, int level, int auxLevel, std::int64_t samples);

  /// Active blocks of the full volume for an isovalue (kept for the last few
  /// isovalues).
  const std::vector<std::int32_t>& ActiveBlocks(double isovalue);

  /// Streaming (see the file's description): from now on no point is
  /// resident; every block's range is empty until RegionArrived() completes
  /// what it reads. Forgets the active lists and the coarse copies.
  void BeginStreaming();
  /// The points first..last (inclusive, per axis) now hold their values.
  /// Residency is kept per run of BlockCells points along each axis (run r:
  /// points 8r .. 8r + 7), so a region covers a run only when it covers all
  /// of it (the volume's last run may be shorter). The blocks this completes
  /// get their ranges (the ranges' value range and missing counts grow with
  /// them); the active lists and coarse copies are forgotten. Returns the
  /// number of blocks that became resident; 0 when not streaming or for a
  /// region outside the volume.
  std::int64_t RegionArrived(const int first[3], const int last[3]);
  /// Ends streaming: the ranges stay as they are (exact once every point
  /// arrived); coarse copies are made again on use.
  void EndStreaming();
  bool IsStreaming() const { return this->Streaming; }
  /// Blocks whose ranges are known (every block when not streaming).
  std::int64_t GetNumberOfResidentBlocks() const;

  /// Streaming: the isovalues whose level-3 surfaces are extracted ahead (see
  /// the file's description). One newly named catches up over the blocks
  /// already resident at the next RegionArrived(); one no longer named is
  /// forgotten. When not streaming only forgets (the surfaces made before
  /// EndStreaming() stay until taken or forgotten).
  void SetAheadIsovalues(const std::vector<double>& isovalues);
  /// The isovalues with a surface under way ahead.
  std::vector<double> GetAheadIsovalues() const;
  /// Completes the surface extracted ahead for `isovalue` and moves it into
  /// `surface`; false (nothing moved) when there is none under way, or it has
  /// not caught up yet. The surface is then no longer held.
  bool TakeAhead(double isovalue, SurfaceArrays& surface);

private:
  struct Typed;
  template <typename T>
  struct TypedImpl;
  struct Ahead;
  // SetVolume's and SetStreamingVolume's start: everything forgotten, the
  // description and its typed implementation taken, no ranges yet; false for
  // a Type that is no ScalarType value.
  bool Adopt(const VolumeDescription& description);
  // Extraction ahead on the blocks RegionArrived() just completed.
  void AdvanceAhead(const std::vector<std::int32_t>& completed);

  TriangleCaseTable Cases;
  ParallelFor Parallel;
  VolumeDescription Description;
  bool Valid = false;
  BlockRanges Ranges;
  std::unique_ptr<Typed> Impl;
  std::vector<std::pair<double, std::vector<std::int32_t>>> ActiveLists;
  // Streaming: the resident runs of points (x fastest) and the blocks whose ranges are known.
  bool Streaming = false;
  int Runs[3] = { 0, 0, 0 };
  std::vector<std::uint8_t> ResidentRuns;
  std::vector<std::uint8_t> ResidentBlocks;
  std::int64_t NumberOfResidentBlocks = 0;
  std::vector<std::unique_ptr<Ahead>> AheadSurfaces;
};

} // namespace mediso

#endif
