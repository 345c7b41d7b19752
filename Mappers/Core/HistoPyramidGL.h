// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file HistoPyramidGL.h
 * @brief The HistoPyramid of a scalar volume, built on the GPU (OpenGL 3.2 core or ES 3.0; no VTK).
 *
 * HistoPyramidGL is the GPU half of cell rasterisation (Liu, Clapworthy &
 * Dong, "Fast isosurface rendering on a GPU by cell rasterization", 2009;
 * section 4.1 of "Hardware Accelerated Medical Data Visualisation on the
 * Web"): it counts, for every cell of a volume, how many of up to
 * MaximumIsovalues isovalues cross it (min < iso <= max over its 8
 * corners, the convention of vtkMarchingCubes), and sums the counts up a 3D
 * 8:1 HistoPyramid (Ziegler, Tevs, Theobalt & Seidel, VMV 2006) with the
 * layout of mediso::PyramidLayout, the same as the CPU model
 * mediso::HistoPyramid, so that both can be compared node for node. A
 * drawing program (IsosurfaceRendererGL) then draws GetTotal() primitives,
 * each finding its cell by walking down the levels.
 *
 * Passes, all render-to-texture with a vertex and a fragment stage only:
 * -# Level 1 from the volume (HistoPyramidFirstLevel_fs.glsl): each texel of
 *    level 1's atlas counts its 4 nodes' cells from their corner values.
 *    Level 0 is never stored. The level is cleared to 0 and only the tiles
 *    whose value range holds an isovalue are drawn: the ranges are computed
 *    once per volume on the CPU, and each build merges the active tiles of a
 *    row into one rectangle (two triangles in a small vertex buffer). A
 *    tile's points are linked by cell edges, so an isovalue in its range
 *    means one of its cells crosses it: the pass costs what the surface
 *    touches, not the volume. With one isovalue each node stores its child
 *    mask (which of its 8 cells cross) in place of its count: the same
 *    bytes, and the walk reads which cells are active with no recount.
 * -# Reductions (HistoPyramidReduce_fs.glsl): each level from the one below,
 *    one full-screen triangle over its atlas.
 * -# Read-back: only the top node comes back to the CPU, as GetTotal().
 *
 * The volume is a 3D texture of the data's own type and bytes, 4 points to
 * a texel along x (RGBA8I/UI, RGBA16I/UI, RGBA32I/UI, RGBA32F; double data
 * is converted to float), read with texelFetch only. Isovalues become
 * thresholds of that type on the CPU (ceil(iso) for integers, the smallest
 * float not below iso for floats), so the GPU's counts equal the CPU's in
 * double precision.
 *
 * Every call saves and restores the GL state it changes (glcore::
 * ScopedGLState), so a host can call it inside its own frame. The context
 * the object was used with (or one sharing its objects) must be current in
 * every call, the destructor and Release() included.
 *
 * @warning Counts are 32-bit: the total must stay below 2^32.
 */
#ifndef MedicalIsosurfaces_HistoPyramidGL_h
#define MedicalIsosurfaces_HistoPyramidGL_h

#include "PyramidLayout.h"
#include "ScalarTypes.h"
#include "VolumeTiles.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mediso
{
class GLApi;
namespace glcore
{
class Program;
}

/**
 * What a drawing program needs to walk a built pyramid down to its cells:
 * primitive k finds the cell and isovalue it draws by descending from the
 * top, at each node choosing the child whose running count holds k (see
 * HistoPyramidIso_vs.glsl). GLSL cannot index an array of samplers with a
 * variable, and each level has its own size, format and atlas layout, so the
 * walk is written for one pyramid layout: one sampler per stored level and
 * one descend() call per level with that level's constants, which the
 * pyramid emits (HistoPyramidGL::GetWalk()) and binds
 * (HistoPyramidGL::BindWalk()) itself.
 */
struct HistoPyramidWalk
{
  /// The volume's value type (VALUE_TYPE, ...), and MEDISO_CHILD_MASKS where level 1 holds child masks.
  std::string Defines;
  /// Snippets for a shader's //MEDISO::HistoPyramidCommon (the volume and
  /// counting code), //MEDISO::HistoPyramidLevels (the level samplers) and
  /// //MEDISO::HistoPyramidDescent (the steps down) hooks (glcore::Hooks).
  std::vector<std::pair<std::string, std::string>> Hooks;
  /// Texture units BindWalk() uses from its first: the volume, then stored levels 1 to top - 1.
  int TextureUnits = 0;
};

class HistoPyramidGL
{
public:
  explicit HistoPyramidGL(std::shared_ptr<const GLApi> gl);
  ~HistoPyramidGL();
  HistoPyramidGL(const HistoPyramidGL&) = delete;
  HistoPyramidGL& operator=(const HistoPyramidGL&) = delete;

  /**
   * Upload `values` (x fastest, `points` per axis, each >= 2) as the volume
   * texture and compute its tile ranges (over `parallel`, serially when it
   * is empty). Replaces the previous volume and invalidates the pyramid.
   * False, with the reason in @a error, when the volume exceeds the
   * context's texture limits or a GL call fails.
   */
  bool UploadVolume(ScalarType type, const void* values, const int points[3],
    const GLParallelFor& parallel, std::string& error);

  /**
   * UploadVolume() of values already as the texture holds them: rows of
   * 4 * PackedVolumeWidth(points[0]) values, padded as PackVolumeRows() pads
   * them (PackVolumeBox() cuts them out of a larger volume), of any type but
   * Float64 (whose texture holds floats: use UploadVolume()). A brick is so
   * sent with the one copy that cuts it out of the host's volume, where
   * UploadVolume() would pad a copy of the copy.
   */
  bool UploadPackedVolume(ScalarType type, const void* packedRows, const int points[3],
    const GLParallelFor& parallel, std::string& error);

  ///@{
  /**
   * A volume whose values arrive region by region (a streamed one,
   * IsosurfaceScene::BeginStreaming()), after UploadVolume() of its first
   * values (the page's empty buffer). EmptyTiles(): every level-1 tile gets
   * an empty range, so that a build counts nothing. UploadRegion(): the
   * points [first, last] (inclusive, per axis) of `values`, the whole volume
   * as UploadVolume() took it (the same type and size, the region's points
   * now holding their values), go into the volume texture as one
   * glTexSubImage3D of the texels that hold them (x widened to whole texels
   * of 4 points), not a whole upload; the tiles whose points meet the region
   * get their range again where `arrived` says every point their cells read
   * holds its value (VolumeTiles::ComputeRegion()). Both invalidate the
   * pyramid: the next Build() counts exactly the cells of the arrived tiles.
   * False, with the reason, without a volume, for a region outside it, or
   * when a GL call fails.
   */
  void EmptyTiles();
  bool UploadRegion(const void* values, const int first[3], const int last[3],
    const PointsArrived& arrived, std::string& error);
  ///@}

  /**
   * Count only the cells [first, end) per axis of the uploaded volume (cell
   * indices; cut to the volume): the others count nothing, in the build and
   * in the walk alike. A brick of a larger volume (IsosurfaceScene) is
   * uploaded with the apron its cells and gradients read and counts only the
   * cells it owns, so that no cell is drawn by two bricks. UploadVolume()
   * resets it to every cell; it invalidates the pyramid.
   */
  void SetOwnedCells(const int first[3], const int end[3]);

  ///@{
  /**
   * A brick pool: the volume texture as a grid of `slots` slots of
   * `slotPoints` points a side (a power of two, 16 or more), each holding
   * one brick of a larger volume or nothing, and one pyramid over all of
   * them (IsosurfaceScene's bricks, HistoPyramidCommon.glsl). A slot's side
   * being a power of two makes it one node of level log2(slotPoints), which
   * Build() reads back as the slot's count (GetSlotTotals()), and from which
   * the walk descends into the slot.
   *
   * AllocatePool() replaces the volume by an empty pool (every slot counts
   * nothing) whose primitives are placed in a volume of `drawnCells`
   * cells. UploadSlot() puts a brick's `points` (each at most slotPoints;
   * its values x fastest) into a slot with glTexSubImage3D, the slot's
   * point 0 being the volume's point `placement`; it keeps counting nothing
   * until SetSlotCells() says which of its cells count (slot-local
   * [first, end); first == end: none, as for a resident brick the
   * isovalues do not cross). SetSlotOrder() gives the frame's order of the
   * slots to draw (their bricks' visibility order), after Build(). Each
   * invalidates the pyramid where the counts change. False, with the reason,
   * where the pool exceeds the context's limits or a GL call fails.
   */
  static constexpr int MaximumSlots = 2048;
  bool AllocatePool(ScalarType type, int slotPoints, const int slots[3], const int drawnCells[3],
    const GLParallelFor& parallel, std::string& error);
  bool UploadSlot(
    int slot, const void* values, const int points[3], const int placement[3], std::string& error);
  /// UploadSlot() of rows already padded, as UploadPackedVolume() takes them.
  bool UploadPackedSlot(int slot, const void* packedRows, const int points[3],
    const int placement[3], std::string& error);
  void SetSlotCells(int slot, const int first[3], const int end[3]);
  void SetSlotOrder(const std::vector<int>& slots);
  bool IsPool() const;
  int GetNumberOfSlots() const;
  /// Per slot, the primitives the last Build() counted in it.
  const std::vector<std::uint32_t>& GetSlotTotals() const;
  ///@}

  /**
   * The cells of the index space the walk places primitives in: the
   * layout's, or a pool's volume (AllocatePool()).
   */
  std::array<int, 3> GetDrawnCells() const;

  /**
   * Compile the build passes' programs once for several pyramids of one
   * context (the bricks of one volume): this pyramid uses `other`'s program
   * cache from now on (Release() lets go of it without freeing it).
   */
  void ShareProgramsWith(const HistoPyramidGL& other);

  /**
   * Build the pyramid of the uploaded volume for 1 to MaximumIsovalues
   * isovalues (NaN ones count nothing) and read back the total.
   */
  bool Build(const std::vector<double>& isovalues, std::string& error);

  ///@{
  /**
   * Build() in two halves, for several pyramids built one after another
   * (the bricks of one volume): BuildPasses() queues the passes and returns
   * without waiting for them; FinishBuild() reads the total (and a pool's
   * slot counts) back, which waits for them. Reading a total back stalls
   * the CPU until the GPU has done everything queued before it, so a scene
   * that queues every brick's passes (and uploads the next bricks meanwhile)
   * before the first read-back waits once per update, not once per brick.
   * The pyramid is built (IsBuilt()) only after FinishBuild(); Build() is
   * the two in turn.
   */
  bool BuildPasses(const std::vector<double>& isovalues, std::string& error);
  bool FinishBuild(std::string& error);
  ///@}

  /**
   * Take `isovalues` as the built pyramid's without building it again, where
   * the caller knows that they count every cell as the last build's did
   * (IsosurfaceScene: a brick that the same values of both sets cross, since
   * a value outside a brick's range crosses none of its cells): the walk
   * uses them from now on (their thresholds, and which surface each cell's
   * crossings belong to). False, with nothing changed, where the pyramid is
   * not built, or where level 1 would hold another thing (child masks for
   * one counted isovalue, counts for several).
   */
  bool AdoptIsovalues(const std::vector<double>& isovalues);

  bool HasVolume() const;
  bool IsBuilt() const;
  /// Primitives (active cell-isovalue pairs) of the last successful Build() (0 before).
  std::uint64_t GetTotal() const;
  /// The layout of the uploaded volume's pyramid.
  const PyramidLayout& GetLayout() const;
  ScalarType GetScalarType() const;

  /**
   * Read a whole level back (x fastest) and its size, for tests. Level 0,
   * which is not stored, is drawn by the crossing code into a temporary
   * texture first. Level 1 comes back as counts even where it holds child
   * masks, unless @a asStored: then as stored.
   */
  bool ReadLevel(int level, std::vector<std::uint32_t>& counts, int size[3], bool asStored,
    std::string& error);

  /**
   * Which of the last Build()'s isovalues the pyramid counts, by index, in
   * the order of bit t of the shaders' crossing masks. Isovalues that can
   * cross no cell of the volume's value type (and NaN ones) are left out.
   */
  const std::vector<int>& GetCountedIsovalues() const;

  /// Whether level 1 holds child masks (one counted isovalue and a level 2 above it).
  bool GetLevelOneHoldsChildMasks() const;

  ///@{
  /// Level-1 tiles of the uploaded volume, and how many the last Build() drew.
  std::uint64_t GetNumberOfTiles() const;
  std::uint64_t GetLastTilesDrawn() const;
  ///@}

  ///@{
  /**
   * The walk of the last successful Build() (empty before one), and its
   * binding: the volume and the levels on texture units `firstUnit` to
   * `firstUnit` + TextureUnits - 1, and the walk's uniforms (samplers,
   * thresholds, cell dimensions, level-1 factors) on `program`, which must be
   * in use and composed with GetWalk()'s defines and hooks.
   */
  HistoPyramidWalk GetWalk() const;
  void BindWalk(glcore::Program& program, int firstUnit) const;
  ///@}

  /// The context's functions the pyramid was made with (a drawing program must use the same).
  const GLApi* GetGLApi() const;

  /// Bytes of GPU memory held now (volume texture and level atlases).
  std::uint64_t GetGPUMemoryBytes() const;

  ///@{
  /**
   * What a volume of `points` per axis and of `type` takes before it is
   * sent, for a host choosing what it can afford: the volume texture's size
   * in texels (4 points to a texel along x; UploadVolume() refuses a volume
   * whose texture exceeds GL_MAX_3D_TEXTURE_SIZE on an axis), and the GPU
   * memory of that texture and of the built pyramid (what
   * GetGPUMemoryBytes() says once the volume is uploaded and built).
   */
  static std::array<int, 3> VolumeTextureSize(const int points[3]);
  static std::uint64_t EstimateGPUMemoryBytes(ScalarType type, const int points[3]);
  ///@}

  /// Frees every GL object (the context must be current). UploadVolume() starts again.
  void Release();

private:
  struct Internals;
  std::unique_ptr<Internals> Impl;
};

} // namespace mediso

#endif
