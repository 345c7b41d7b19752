// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkBlockLODContour
 * @brief   Block-based level-of-detail isosurfaces of image data, with a
 *          triangle cache, a memory estimator and automatic level choice.
 *
 * vtkBlockLODContour is the CPU isosurface method of "Hardware Accelerated
 * Medical Data Visualisation on the Web" (section 4.2): marching cubes over
 * 8x8x8-cell blocks at four levels of detail, for clients that cannot use the
 * GPU path, that need geometry to process further, or that must fit a memory
 * budget. The method is the VTK-free core in Filters/Core, which documents
 * it: BlockLOD.h (blocks, levels, point merging, normals), BlockLODVolume.h
 * (one input with its block ranges and coarse copies), BlockLODEstimator.h
 * (the memory and time estimates, the level choice), BlockLODCache.h (the
 * (isovalue, level) surface cache) and BlockLODSurfaces.h (all of them behind
 * one update, as the web page runs them too). This class converts the input
 * and output and runs, per update: check the input, describe it to the core
 * (block ranges refreshed when it changed), let the core choose the level,
 * plan it and generate the surfaces, assemble the output. In short:
 *
 * -# Block ranges. The minimum and maximum of every block are computed once
 *    per input array (in parallel) and kept until the input data, the array or
 *    its values change. For each isovalue only the blocks whose range straddles
 *    it are visited.
 * -# Levels. LOD 0..3 samples with cube edges of 8, 4, 2, 1 voxels; LOD 3 is
 *    full resolution and gives the same surface as vtkFlyingEdges3D or
 *    vtkMarchingCubes (same case table: VTK's vtkMarchingCubesTriangleCases).
 *    Every level is watertight: points on shared edges are merged within and
 *    across blocks.
 * -# Coarse copies. Levels 0-2 are extracted from a contiguous copy of the
 *    level's samples, made the first time the level is used on an input and
 *    kept with the block ranges (1/512, 1/64, 1/8 of the input's memory for
 *    levels 0, 1, 2): the same cubes, read from a small array instead of
 *    scattered through the full volume.
 * -# Cache. Each (isovalue, level) surface is kept after extraction, within
 *    CacheMemoryLimit (least recently used surfaces go first). Asking again
 *    for a cached pair costs no extraction (see GetNumberOfExtractions()).
 *    A surface the cache drops to make room lends its memory to the new one
 *    when nothing else holds its arrays, so that changes with a full cache
 *    (an isovalue dragged) write into pages already mapped.
 * -# Estimates. EstimateTriangles()/EstimateMegabytes()/EstimateSeconds()
 *    predict a pair's output before extracting it (BlockLODEstimator.h).
 *    Exact for a cached or planned pair, and for a new pair whose active
 *    blocks can all be counted within a fixed amount of work (levels 0 and 1
 *    almost always). Otherwise the cut cubes and edges are counted on a spread
 *    sample of active blocks together with the finest coarser level whose
 *    count is exact, and scaled by that level's exact count (a ratio
 *    estimate); the paper used a fixed 2 triangles per cube instead. Bytes are
 *    those the output vtkPolyData holds (points, normals, scalars,
 *    connectivity, offsets, block ids); seconds (the paper's future work)
 *    are those of an update that extracts the pair, from a cost model (per
 *    visited cube, per triangle and per update) fitted to the updates of
 *    every vtkBlockLODContour in the process (it describes the machine).
 * -# AutoLOD. With AutoLOD on, the filter picks the highest level whose
 *    estimated output fits MemoryBudget (MB, all isovalues together). Exact
 *    counts are known before any output is allocated, so an underestimate
 *    never pushes the process past the budget: the filter drops to a coarser
 *    level and warns. If even level 0 does not fit, it reports an error and
 *    produces nothing. A budget larger than what the process may still
 *    allocate (ProcessMemory.h: free memory, `ulimit -v`, a cgroup's limit)
 *    is not trusted: the level fits the smaller of the two, with a warning
 *    when the process's allowance lowered it.
 * -# Memory. Every plan, surface and merged output is checked against what
 *    the process may still allocate before it is allocated; one that does not
 *    fit gives one error naming it and an empty output, and a failed
 *    allocation (std::bad_alloc) never leaves RequestData.
 *
 * Output: triangles (64-bit connectivity, VTK's own; 32-bit while it fits
 * with CompactIds), point normals ("Normals", optional), the isovalue as
 * point scalars (optional), the block id of each triangle ("BlockId",
 * optional), and field data "BlockLODLevel" (the level used),
 * "BlockLODEstimatedTriangles", "BlockLODEstimatedMB" and
 * "BlockLODEstimatedSeconds" (4 values each, levels 0..3, for the first
 * isovalue). The points', normals' and scalars' value ranges are measured
 * while they are written and stored with the arrays (VTK's range cache), so
 * ParaView's data information and color maps do not read them again.
 *
 * Other levels of the same output: GenerateLevel() fills a vtkPolyData with
 * the last update's isovalues at another level (from the cache, or extracted
 * once and cached), and EstimateLevelTriangles() predicts its size first.
 * ParaView's render view draws such a coarser level while the camera moves
 * (vtkBlockLODSurfaceRepresentation), instead of a decimated copy.
 *
 * Parallel pieces: every level samples the whole volume's grid (multiples of
 * the level's stride from the whole extent's origin, and the whole extent's
 * last point), not the piece's. A piece of a parallel run asks its input for
 * 2 * 8 - 1 ghost layers more than its output needs (enough for a level-0
 * cube past the piece and the normals at its far corner; one layer when the
 * run has one piece) and makes no triangle in ghost cells (vtkGhostType, or
 * the piece's extent without ghosts when a filter upstream dropped that
 * array). So at every level the pieces' triangles are exactly the
 * one-process triangles (no duplicates, no cracks), with the same normals,
 * and "BlockId" numbers the whole volume's blocks.
 * @warning With AutoLOD each piece picks its level from its own estimate: in
 * a parallel run set LOD explicitly for one seamless surface. In a piece an
 * isovalue outside that piece's range is not a warning (the piece is empty).
 * @warning The triangle offsets (0, 3, 6, ...) of every output are views of
 * one read-only run that all of the process's outputs share (no output writes
 * or faults in its own). Appending cells (InsertNextCell, Append) copies them
 * first, but writing into an output's offsets in place (SetValue on
 * GetOffsetsArray(), or Reset() and then new cells) would change every
 * output's: DeepCopy an output before editing its cells in place (editing
 * it in place would change the filter's cached surface as well).
 *
 * Inputs: vtkImageData with a one-component point array of type char, signed
 * char, unsigned char, short, unsigned short, int, unsigned int, float or
 * double: the one named by SetInputArrayToProcess (ParaView's ContourBy), or,
 * when none is named, the active point scalars if they have one component,
 * else the only one-component point array. Spacing, origin and extent are
 * honoured, and so is a direction matrix, as vtkFlyingEdges3D honours it
 * (vtkImageTransform): the surface is made on the grid without the direction,
 * then its points go to origin + D (x - origin) and its normals to
 * det(D) D n, the triangles unchanged, so a mirror image (det -1) keeps the
 * orientation VTK's filters give. Cached surfaces are stored placed; a change
 * of the direction alone drops them. A direction that is not orthonormal
 * (sheared, singular, non-finite; tolerance 1e-3) is an error. NaN and infinite
 * values are missing data: cubes touching them make no triangle (one warning
 * per input), so the output holds only finite points. Bad input (no point
 * array, a named array the input lacks or a cell array, several components,
 * 2D data, zero or non-finite spacing, a direction that is not orthonormal,
 * an unsupported type, a constant or
 * all-NaN volume, an isovalue outside the data range, a budget too small)
 * gives one error or warning saying what is wrong, and an empty or partial
 * output, never a crash. Passes run with vtkSMPTools; progress is reported and
 * abort honoured between passes and blocks.
 *
 * @sa vtkFlyingEdges3D vtkMarchingCubes vtkContourValues
 */
#ifndef vtkBlockLODContour_h
#define vtkBlockLODContour_h

#include "MedicalIsosurfacesFiltersModule.h" // For export macro
#include "vtkContourValues.h"                // For inline methods
#include "vtkNew.h"                          // For vtkNew
#include "vtkPolyDataAlgorithm.h"

#include <memory> // For std::unique_ptr
#include <vector> // For the steps' isovalues

class vtkDataArray;
class vtkImageData;
class vtkPolyData;
namespace mediso
{
struct SurfacesUpdate;
}

class MEDICALISOSURFACESFILTERS_EXPORT vtkBlockLODContour : public vtkPolyDataAlgorithm
{
public:
  static vtkBlockLODContour* New();
  vtkTypeMacro(vtkBlockLODContour, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Isovalues, as in the other VTK contour filters.
   */
  void SetValue(int i, double value) { this->ContourValues->SetValue(i, value); }
  double GetValue(int i) { return this->ContourValues->GetValue(i); }
  double* GetValues() { return this->ContourValues->GetValues(); }
  void GetValues(double* contourValues) { this->ContourValues->GetValues(contourValues); }
  void SetNumberOfContours(int number) { this->ContourValues->SetNumberOfContours(number); }
  vtkIdType GetNumberOfContours() { return this->ContourValues->GetNumberOfContours(); }
  void GenerateValues(int numContours, double range[2])
  {
    this->ContourValues->GenerateValues(numContours, range);
  }
  void GenerateValues(int numContours, double rangeStart, double rangeEnd)
  {
    this->ContourValues->GenerateValues(numContours, rangeStart, rangeEnd);
  }
  ///@}

  ///@{
  /**
   * Level of detail 0..3 (cube edges of 8, 4, 2, 1 voxels) used when AutoLOD
   * is off. Default 3 (full resolution). A value outside 0..3 is rejected
   * with an error and the level stays as it was (a client of a pvserver sees
   * the error instead of a silently clamped level).
   */
  void SetLOD(int level);
  vtkGetMacro(LOD, int);
  ///@}

  ///@{
  /**
   * Choose the level automatically: the highest one whose estimated output
   * fits MemoryBudget. Default off.
   */
  vtkSetMacro(AutoLOD, bool);
  vtkGetMacro(AutoLOD, bool);
  vtkBooleanMacro(AutoLOD, bool);
  ///@}

  ///@{
  /**
   * Memory budget of the output in MB (10^6 bytes) for AutoLOD. Default 256.
   */
  vtkSetClampMacro(MemoryBudget, double, 0.0, 1.0e9);
  vtkGetMacro(MemoryBudget, double);
  ///@}

  ///@{
  /**
   * Output point normals from the gradient of the original data. Default on.
   */
  vtkSetMacro(ComputeNormals, bool);
  vtkGetMacro(ComputeNormals, bool);
  vtkBooleanMacro(ComputeNormals, bool);
  ///@}

  ///@{
  /**
   * Output the isovalue as point scalars. Default off.
   */
  vtkSetMacro(ComputeScalars, bool);
  vtkGetMacro(ComputeScalars, bool);
  vtkBooleanMacro(ComputeScalars, bool);
  ///@}

  ///@{
  /**
   * Output the block id of each triangle as cell data "BlockId". Default off.
   */
  vtkSetMacro(GenerateBlockIds, bool);
  vtkGetMacro(GenerateBlockIds, bool);
  vtkBooleanMacro(GenerateBlockIds, bool);
  ///@}

  ///@{
  /**
   * Store the triangles' point ids in 32 bits while they fit (a third less
   * output memory) instead of VTK's own 64-bit vtkIdType. Default off: VTK's
   * mappers and filters read 64-bit cell arrays in place but copy 32-bit ones
   * cell by cell (ParaView's upload of a 650k-triangle surface takes about
   * 30 ms longer), so compact ids suit a memory-bound client, not a renderer.
   */
  vtkSetMacro(CompactIds, bool);
  vtkGetMacro(CompactIds, bool);
  vtkBooleanMacro(CompactIds, bool);
  ///@}

  ///@{
  /**
   * Memory (MB) the triangle cache may hold; 0 disables caching. Default 512.
   */
  vtkSetClampMacro(CacheMemoryLimit, double, 0.0, 1.0e9);
  vtkGetMacro(CacheMemoryLimit, double);
  ///@}

  ///@{
  /**
   * Estimates for one (isovalue, level) pair on the current input (the input
   * must have been updated; RequestData-free: no extraction is run). -1 when
   * the input is unusable.
   */
  double EstimateTriangles(double isovalue, int level);
  double EstimateMegabytes(double isovalue, int level);
  double EstimateSeconds(double isovalue, int level);
  ///@}

  /**
   * How the last estimate was made: 0 exact (cached, planned or every active
   * block counted), 1 counted on sampled blocks and scaled by the exact count
   * of a coarser level of the same isovalue, 2 counted on sampled blocks and
   * scaled up to all active blocks, -1 none.
   */
  vtkGetMacro(LastEstimateMethod, int);

  ///@{
  /**
   * Estimates per level (0..3) for the isovalues set now, all of them
   * together, on the volume of the last update: what an update would cost
   * before it runs (an isovalue change answered at a coarse level first,
   * medical_isosurfaces.RefineAfterChange, reads them as information
   * properties). Each call estimates anew (no extraction is run); -1 for a
   * level when there is no estimate (no update yet, no isovalue).
   */
  double* GetCurrentEstimatedSeconds() VTK_SIZEHINT(4);
  double* GetCurrentEstimatedMegabytes() VTK_SIZEHINT(4);
  ///@}

  /**
   * The estimated triangles per level (0..3) for the isovalues set now, as
   * GetCurrentEstimatedSeconds() estimates (-1 where there is no estimate):
   * what a first answer's frame would draw, which the display's frame-time
   * model predicts (vtkBlockLODSurfaceRepresentation::GetPredictedStillSeconds()).
   */
  double* GetCurrentEstimatedTriangles() VTK_SIZEHINT(4);

  /**
   * Level used by the last execution (-1 before any, or when nothing was made).
   */
  vtkGetMacro(ChosenLevel, int);

  ///@{
  /**
   * Estimates per level (0..3) for the first isovalue, from the last execution
   * (reported to ParaView as read-only properties).
   */
  vtkGetVector4Macro(EstimatedTriangles, double);
  vtkGetVector4Macro(EstimatedMegabytes, double);
  vtkGetVector4Macro(EstimatedSeconds, double);
  ///@}

  ///@{
  /**
   * Work counters, for tests and benchmarks: marching-cubes extractions run,
   * (isovalue, level) requests served from the cache, block-range passes.
   */
  vtkGetMacro(NumberOfExtractions, vtkIdType);
  vtkGetMacro(NumberOfCacheHits, vtkIdType);
  vtkGetMacro(NumberOfBlockRangeComputations, vtkIdType);
  ///@}

  /**
   * The last update's surfaces at another level of detail, into `output`:
   * the same isovalues, arrays and options as the output, field data
   * "BlockLODLevel" set to `level`. Taken from the cache, or extracted now and
   * cached (counted in GetNumberOfExtractions()), so a second call is free.
   * This is how a renderer gets a coarser copy of the output to draw while
   * the camera moves (vtkBlockLODSurfaceRepresentation). Returns false and
   * leaves `output` empty when there is no current output to match: before
   * the first update, after a change of the filter or its input array that
   * has not been updated yet, when the last update made nothing, or for a
   * level outside 0..3. A level that does not fit in the process's memory
   * gives one warning and false. No output port or pipeline request is
   * involved: the filter's own output is not touched.
   */
  bool GenerateLevel(int level, vtkPolyData* output);

  /**
   * Triangles of the last update's isovalues, all together, at `level`:
   * exact when the level is the output's, cached or planned, else the
   * estimator's prediction (EstimateTriangles). -1 when there is no current
   * output (as for GenerateLevel).
   */
  double EstimateLevelTriangles(int level);

  /**
   * Empty the triangle cache (block ranges are kept).
   */
  void ClearCache();

  /**
   * Bytes held by the triangle cache.
   */
  double GetCacheMegabytes();

  vtkMTimeType GetMTime() override;

protected:
  vtkBlockLODContour();
  ~vtkBlockLODContour() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int FillInputPortInformation(int port, vtkInformation* info) override;

  vtkNew<vtkContourValues> ContourValues;
  int LOD = 3;
  bool AutoLOD = false;
  double MemoryBudget = 256.0;
  bool ComputeNormals = true;
  bool ComputeScalars = false;
  bool GenerateBlockIds = false;
  bool CompactIds = false;
  double CacheMemoryLimit = 512.0;

  int ChosenLevel = -1;
  int LastEstimateMethod = -1;
  double EstimatedTriangles[4] = { 0, 0, 0, 0 };
  double EstimatedMegabytes[4] = { 0, 0, 0, 0 };
  double EstimatedSeconds[4] = { 0, 0, 0, 0 };
  double CurrentEstimatedSeconds[4] = { -1, -1, -1, -1 };
  double CurrentEstimatedMegabytes[4] = { -1, -1, -1, -1 };
  double CurrentEstimatedTriangles[4] = { -1, -1, -1, -1 };
  vtkIdType NumberOfExtractions = 0;
  vtkIdType NumberOfCacheHits = 0;
  vtkIdType NumberOfBlockRangeComputations = 0;

private:
  vtkBlockLODContour(const vtkBlockLODContour&) = delete;
  void operator=(const vtkBlockLODContour&) = delete;

  // The steps of RequestData, in order (ChooseArray is part of CheckInput).
  vtkDataArray* ChooseArray(vtkImageData* input, vtkInformationVector** inputVector);
  vtkDataArray* CheckInput(vtkImageData* input, vtkInformationVector** inputVector);
  // Execute runs them; `step` names the one running (for a message when
  // memory runs out). Choosing, planning and generating are the core's
  // (BlockLODSurfaces); ReportUpdate says what they did.
  void Execute(vtkInformationVector** inputVector, vtkImageData* input, vtkPolyData* output,
    const char*& step);
  std::vector<double> IsovaluesWithSurface();
  void ReportEstimates(double isovalue);
  void ReportUpdate(const mediso::SurfacesUpdate& update);
  bool AssembleOutput(vtkPolyData* output, int level);
  // The last update's output can be matched by GenerateLevel.
  bool HasCurrentOutput();

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
