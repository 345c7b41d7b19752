// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BlockLODEstimator.h
 * @brief The memory and time estimator of the block LOD method (no VTK): the
 * paper's answer to a client's memory limit, and the level choice it drives.
 *
 * - SurfaceLayout turns point and triangle counts into the bytes a host's
 *   output holds (float points, optional float normals and scalars, 64-bit
 *   ids or 32-bit ones while they fit, optional offsets as in a vtkCellArray,
 *   optional 32-bit block ids per triangle).
 * - CostModel predicts the seconds of an update that extracts a pair, from
 *   the cubes it visits and the triangles it makes (see the class).
 * - BlockLODEstimator predicts an (isovalue, level) pair's counts before it is
 *   extracted, in this order:
 *   -# exact, for a pair whose plan was recorded (RecordExact), or that can be
 *      counted on every active block within SampleBudget (levels 0 and 1 on
 *      their small coarse copies, finer levels with few active blocks);
 *   -# counted on a jittered systematic sample of active blocks (as many as
 *      the budget pays for), together with the finest coarser level whose
 *      count is exact (made exact within the budget when it is not): the
 *      blocks that level cuts give a ratio estimate (its exact count times
 *      the sample's ratio of the two levels' counts: per-block counts of two
 *      levels move together, so the ratio varies far less than the counts),
 *      the blocks it does not cut are scaled up from the sample;
 *   -# without such a level, the sample scaled up to all active blocks (the
 *      paper used a fixed 2 triangles per cube instead).
 *   Sampled estimates are kept until Reset() (the input changed).
 * - ChooseLevel() picks the highest level whose estimated output, all
 *   isovalues together, fits a byte budget (AutoLOD). A host plans the chosen
 *   level before allocating and drops a level when the exact bytes do not fit,
 *   so a low estimate never exceeds the budget.
 */
#ifndef MedicalIsosurfaces_BlockLODEstimator_h
#define MedicalIsosurfaces_BlockLODEstimator_h

#include "BlockLODVolume.h"

#include <cstdint>
#include <map>
#include <vector>

namespace mediso
{

/// Bytes of an output surface in the host's layout.
struct SurfaceLayout
{
  bool Normals = true;   ///< 3 floats per point.
  bool Scalars = false;  ///< 1 float per point.
  bool BlockIds = false; ///< 1 int32 per triangle.
  bool Offsets = true;   ///< 1 id per triangle and 1 more (vtkCellArray); off for an index buffer.
  /// 8: 64-bit ids; 4: 32-bit ids while they fit (else 64-bit).
  int IdBytes = 8;

  /// True when point ids or connectivity entries do not fit 32-bit ids.
  static bool NeedsWideIds(double points, double triangles);
  /// Bytes of one id for a surface of this size.
  int IdBytesFor(double points, double triangles) const
  {
    return this->IdBytes == 4 && !NeedsWideIds(points, triangles) ? 4 : 8;
  }
  double Bytes(double points, double triangles) const;
  double Bytes(const SurfaceCounts& c) const { return this->Bytes(c.Points, c.Triangles); }
  bool operator==(const SurfaceLayout& o) const
  {
    return this->Normals == o.Normals && this->Scalars == o.Scalars &&
      this->BlockIds == o.BlockIds && this->Offsets == o.Offsets && this->IdBytes == o.IdBytes;
  }
  bool operator!=(const SurfaceLayout& o) const { return !(*this == o); }
};

/// Seconds of an update that extracts surfaces at a level, from the cubes it
/// visits and the triangles it makes. Defaults A * cubes + B * triangles + C
/// (C: the update's fixed work, such as checks, estimates and output
/// assembly) are scaled to match the level's records (one parameter, stable
/// from the first record; the records of all levels before the level has
/// one). Once a level has MinimumRecords records, its own A, B and C, fitted
/// by least squares, predict instead, unless they stray more than 3x from the
/// scaled defaults. Fits are on relative errors (weights 1 / seconds^2,
/// seconds no less than the prediction: a 10 ms update counts as much as a
/// 1 s one, a spuriously fast one no more), older records fading by Memory per
/// new one so the model follows the machine's load; a record more than twice
/// off the prediction (a disturbed update: another process held a core)
/// counts a tenth.
class CostModel
{
public:
  /// Rates until the host's own updates are recorded (a 2-core machine).
  static constexpr double DefaultSecondsPerCube = 4.0e-9;
  static constexpr double DefaultSecondsPerTriangle = 1.2e-8;
  static constexpr double DefaultSecondsPerUpdate = 1.0e-3;
  /// Weight a record keeps when a new one arrives.
  static constexpr double Memory = 0.97;
  /// Weight of a record more than twice off the prediction.
  static constexpr double OutlierWeight = 0.1;
  /// Records a fit needs before it predicts (three would fit any three points).
  static constexpr int MinimumRecords = 5;

  void Record(int level, double cubes, double triangles, double seconds);
  double Predict(int level, double cubes, double triangles) const;
  double Predict(int level, const SurfaceCounts& c) const
  {
    return this->Predict(level, c.Cubes, c.Triangles);
  }
  int GetNumberOfSamples() const { return this->All.Samples; }
  void Reset() { *this = CostModel(); }

private:
  // Weighted normal equations of (cubes, triangles, 1) -> seconds, and of the
  // one-parameter fit "scale * defaults".
  struct Fit
  {
    double Normal[3][3] = { { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 } };
    double Right[3] = { 0, 0, 0 };
    double ScaleNumerator = 0;
    double ScaleDenominator = 0;
    int Samples = 0;
    void Record(double cubes, double triangles, double seconds, double weight);
    // The fitted A, B, C when there are MinimumRecords records and all are >= 0.
    bool Solve(double abc[3]) const;
  };
  static double Default(double cubes, double triangles);
  Fit Levels[NumberOfLevels];
  Fit All;
};

/// How an estimate was made (values as vtkBlockLODContour::GetLastEstimateMethod()).
enum class EstimateMethod
{
  None = -1,
  Exact = 0,   ///< Every active block counted, or the pair planned.
  Scaled = 1,  ///< Sampled, scaled by the exact count of a coarser level.
  Sampled = 2  ///< Sampled, scaled up to all active blocks.
};

struct SurfaceEstimate
{
  SurfaceCounts Counts;
  EstimateMethod Method = EstimateMethod::None;
};

class BlockLODEstimator
{
public:
  /// The work one estimate may do by default, in BlockLODVolume::BlockCost()
  /// units: about 1024 blocks of level 3 (a millisecond or two on 2 cores).
  static constexpr double DefaultSampleBudget = 13.0 * 1024;
  /// The fewest blocks a sampled estimate counts, whatever the budget.
  static constexpr std::int64_t MinimumSamples = 256;

  explicit BlockLODEstimator(BlockLODVolume& volume);

  /// Forgets every count (the volume changed).
  void Reset();

  /// Counts of an (isovalue, level) pair (see the file's description).
  SurfaceEstimate Estimate(double isovalue, int level);
  /// Records a pair's exact counts (from BlockLODVolume::CountsOf(plan)).
  void RecordExact(double isovalue, int level, const SurfaceCounts& counts);
  bool HasExact(double isovalue, int level) const;

  /// Predicted seconds of an update that extracts a pair, by a cost model.
  double EstimateSeconds(double isovalue, int level, const CostModel& model);

  /// The highest level whose estimated bytes for all `isovalues` together fit
  /// `budgetBytes`, or -1 when not even level 0 fits; `level0Bytes` receives
  /// the estimate at level 0 when none fits.
  int ChooseLevel(const std::vector<double>& isovalues, double budgetBytes,
    const SurfaceLayout& layout, double& level0Bytes);

  /// The work one estimate may do (see DefaultSampleBudget); a change
  /// applies to estimates not made yet.
  void SetSampleBudget(double budget) { this->SampleBudget = budget; }
  double GetSampleBudget() const { return this->SampleBudget; }


private:
  BlockLODVolume& Volume;
  std::map<SurfaceKey, SurfaceCounts> Exact;
  std::map<SurfaceKey, SurfaceEstimate> Sampled;
  double SampleBudget = DefaultSampleBudget;
};

} // namespace mediso

#endif
