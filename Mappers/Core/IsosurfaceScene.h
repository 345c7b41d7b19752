// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file IsosurfaceScene.h
 * @brief The GPU render module as one unit: a volume, its isosurfaces, and
 * the frames drawn of them (OpenGL 3.2 core or ES 3.0; no VTK).
 *
 * Every host of the GPU path (the ParaView mapper's shell
 * vtkOpenGLHistoPyramidIsosurfaces, mediso-render, the web page's
 * WebViewer) drives the same three calls, and nothing else of the core:
 *
 * -# SetVolume(): the volume, described by a VolumeDescription (its type,
 *    values, size and the host's Stamp of the values). It is uploaded only
 *    when one of these changes; the pyramid is then built again.
 * -# SetSurfaces(): the isosurfaces, normalised once for every host
 *    (Normalize(): NaN values left out, increasing values, each once, at
 *    most MaximumIsovalues, with the reason for what is left out).
 * -# Render(): the frame (camera, lights, material, footprint options; its
 *    surfaces are the scene's), after Update(), which builds the pyramid
 *    when the surfaces' values or the volume changed since the last build.
 *    Camera moves reuse the uploaded volume and the built pyramid.
 *
 * Interactive frames can draw a coarse level instead (IsosurfaceFrame::Level
 * 2, 1 or 0): the volume sampled at Block LOD's strides 2, 4 or 8, the points
 * vtkBlockLODContour's levels sample (MakeCoarseCopy() in BlockLOD.h), with
 * its own texture and pyramid, made on the level's first frame and built
 * again when the isovalues change (UpdateLevel()). On a software rasteriser
 * the GPU path's frame is bound by its primitives (each walks the pyramid in
 * the vertex stage), which a coarse level divides by about stride^2 where
 * fewer pixels do not help. Below Block LOD's levels, level -1
 * (CoarsestLevel, stride 16) is the GPU path's alone: where level 0's
 * primitives are still over a host's budget (a 512^3 volume on a software
 * WebGL2), it divides them by about 4 again; made the same way, from
 * MakeStrideCopy(), its cells a whole stride long as level 0's.
 *
 * These are the scene's one upload decision and one build decision, as
 * vtkOpenGLGPUVolumeRayCastMapper keeps one ShaderRebuildNeeded predicate;
 * GetStats() says what they did, in one structure the hosts forward whole.
 * Inside, HistoPyramidGL builds the pyramid (and owns its walk) and
 * IsosurfaceRendererGL draws it; no host includes either.
 *
 * A volume over one 3D texture (GL_MAX_3D_TEXTURE_SIZE on an axis, or
 * SetMaxTextureSize()) or over the GPU-memory budget (SetGPUMemoryBudget())
 * is kept as bricks instead (mediso::BrickGrid, BrickGrid.h): SetVolume()
 * uploads nothing but computes every brick's value range; Update() finds
 * the bricks the isovalues cross, uploads those not resident (each with the
 * apron its cells and gradients read, least recently used ones evicted to
 * stay within the budget) into the slots of one pool texture and builds one
 * pyramid over the pool that counts only the cells each slot's brick owns;
 * Render() draws it in one pass, its slots walked in the bricks' visibility
 * order (nearest brick first, farthest first for translucent surfaces), each
 * cell placed at its brick through the slot table (SetBrickPool()). Where
 * the pool cannot hold the active bricks, each is its own texture and
 * pyramid, drawn as pieces in that order. Every cell is counted by exactly
 * one brick, so the primitives are the one-texture count exactly. Where the
 * active bricks alone exceed the budget, Update() fails with that reason
 * (GetStats().OverBudget), and the host falls back as for any other reason.
 * Bricks read the host's values when they become active: Data must stay
 * valid while it is the scene's volume (every host passes it to SetVolume()
 * before each Update()).
 *
 * The context of SetContext() (or one sharing its objects) must be current
 * in every call that touches GL: SetVolume(), Update(), Render(),
 * Release() and the destructor. Release() frees every GL object but keeps
 * the surfaces and the counts of GetStats(), so that a host can move the
 * scene to another context (SetContext()) as VTK moves a mapper to another
 * window.
 */
#ifndef MedicalIsosurfaces_IsosurfaceScene_h
#define MedicalIsosurfaces_IsosurfaceScene_h

#include "BlockLODVolume.h" // VolumeDescription
#include "IsosurfaceFrame.h"
#include "VolumeTiles.h" // GLParallelFor

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace mediso
{
class GLApi;

/// A list of isosurfaces as the scene draws them, and what was left out of the list given.
struct SurfaceSelection
{
  /// Increasing values, each once, at most MaximumIsovalues.
  std::vector<IsosurfaceLook> Surfaces;
  /// For each of Surfaces, its index in the list given.
  std::vector<int> Sources;
  /// How many values of the list given are NaN (left out).
  int NotANumber = 0;
  /// Values given more than once, in increasing order (each drawn once, with its first look).
  std::vector<double> Repeated;
  /// Distinct values given (the lowest MaximumIsovalues of them are kept).
  std::size_t Distinct = 0;
  /// One sentence for each kind of value left out: the NaN ones, those over the limit.
  std::vector<std::string> Notes;
};

class IsosurfaceScene
{
public:
  /// `parallel` runs the volume's CPU work (packing, tile ranges); empty: serially.
  explicit IsosurfaceScene(GLParallelFor parallel);
  ~IsosurfaceScene();
  IsosurfaceScene(const IsosurfaceScene&) = delete;
  IsosurfaceScene& operator=(const IsosurfaceScene&) = delete;

  /**
   * Draw with `gl`'s context from now on. A scene that holds GL objects
   * must be Release()d first (in its old context).
   */
  void SetContext(std::shared_ptr<const GLApi> gl);
  bool HasContext() const;

  /**
   * Adopt a volume: uploaded when its Type, Data, Dims or Stamp differ from
   * the current volume's (the rest of the description does not change the
   * GPU's copy). A volume over the texture limit or the GPU budget is
   * adopted as bricks (its ranges computed, nothing uploaded until
   * Update()). False, with the reason in @a error, when it cannot be
   * uploaded (a GL failure, memory, a texture limit below the smallest
   * brick); the scene then has no volume until one uploads. The values stay
   * the host's: they must stay valid while the scene holds the volume, since
   * a coarse level (UpdateLevel()) is sampled from them on its first frame.
   */
  bool SetVolume(const VolumeDescription& volume, std::string& error);
  bool HasVolume() const;

  ///@{
  /**
   * Where a volume is kept as bricks. SetMaxTextureSize(): the largest 3D
   * texture side the scene uses (0, the default: the context's
   * GL_MAX_3D_TEXTURE_SIZE; a smaller one makes tests brick a small volume).
   * SetGPUMemoryBudget(): the bytes the volume's textures and pyramids may
   * take on the GPU (0, the default: half of the device's memory where the
   * context tells it, GLApi::GetDeviceMemoryBytes(), else
   * DefaultGPUMemoryBudget; GetGPUMemoryBudget() says which). A volume whose
   * one texture exceeds either is kept as bricks. A change takes effect at
   * the next SetVolume(), which then uploads again.
   */
  void SetMaxTextureSize(int texels);
  int GetMaxTextureSize() const;
  void SetGPUMemoryBudget(std::uint64_t bytes);
  std::uint64_t GetGPUMemoryBudget() const;
  /// The budget where none is set and the context does not tell the device's memory (WebGL2,
  /// OpenGL ES, Mesa): 1 GiB, what a WebGL2 page can expect of most devices.
  static constexpr std::uint64_t DefaultGPUMemoryBudget = std::uint64_t(1) << 30;
  /// Whether the current volume is kept as bricks.
  bool IsBricked() const;
  ///@}

  ///@{
  /**
   * The brick pool (on by default): a volume kept as bricks holds its
   * resident bricks as the slots of one 3D texture within the texture limit
   * and the budget (each slot a power of two a side, 16 points or more,
   * holding a brick with its apron), with an indirection per slot (the
   * brick's place in the volume and the cells it owns) and one pyramid over
   * the pool, built once per isovalue change and drawn in one pass. The
   * bricks are those of ChooseBrickPoints(), pool or not. Where the pool
   * cannot hold the active bricks within the limit and the budget (a forced
   * limit near the brick's size leaves room for few slots), or where it would
   * take more than MaximumPoolMemoryRatio times the GPU memory of the same
   * bricks as their own pyramids (bricks thinner than their cubic slots, as a
   * long thin volume's: 96x96x251 points in slots of 256), they are drawn as
   * their own pyramids, as with the pool off, and GetBrickPoolReason() says
   * why. The choice is made again at every isovalue change for the bricks
   * the new isovalues cross: a pool is kept while it holds them within that
   * ratio, else weighed as a new one (a pool made for many bricks gives way
   * to a smaller one, or to the bricks' own pyramids, when the isovalues
   * come to cross few; bricks that the pool now holds within the ratio are
   * drawn from one again). Turning the pool on or off takes effect at the
   * next SetVolume().
   */
  void SetBrickPool(bool on);
  bool GetBrickPool() const;
  ///@}

  ///@{
  /**
   * Whether the first-hit pass drops hidden points (IsosurfaceRendererGL::SetHitCull()):
   * HitCull::Auto (the default) on hardware renderers only, On or Off everywhere. The
   * image is the same either way; GetStats().HitCull says whether the last frame did.
   */
  void SetHitCull(HitCull mode);
  HitCull GetHitCull() const;
  ///@}

  /**
   * The most GPU memory a pool may take, made or kept, as a multiple of the active
   * bricks' own pyramids (each brick's texture and its pyramid padded to
   * powers of two): 3. A cube brick's slot alone costs up to 1.66x its own
   * pyramid (27 points in 32: the texture's margin), a volume's last bricks
   * on an axis are thinner than the others but take whole slots, and a pool
   * made with room for the next power of two of bricks costs up to 2x more;
   * where that room would exceed the ratio the pool is made for the active
   * bricks alone, and where that still would, there is no pool. Bricks thin
   * on a whole axis (96x96x251 points in slots of 256: 6.8x) stay out.
   */
  static constexpr double MaximumPoolMemoryRatio = 3.0;

  /**
   * Why the last update of a volume kept as bricks drew its active bricks
   * as their own pyramids and not from the pool (the pool off, a pool over
   * the limit or the budget, or over MaximumPoolMemoryRatio, with its bytes
   * and the bricks'), or that the active bricks alone are over the budget
   * (the update failed: neither draws them); "" where the pool holds them or
   * the volume is one texture.
   */
  std::string GetBrickPoolReason() const;

  /**
   * The brick edge (points, a multiple of 8) for a volume of `type` under a
   * texture limit and a budget: the largest 2^k - 8 (so that a brick's
   * cells with its apron, edge + 2, fit a pyramid of 2^k cells a side) up to
   * 248 whose textures fit the limit and an eighth of the budget; 8 at least.
   */
  static int ChooseBrickPoints(ScalarType type, int maxTextureSize, std::uint64_t budget);

  ///@{
  /**
   * Streaming: a volume whose values arrive region by region (the web page's
   * bricks, docs/web.md "Streaming"), kept as one texture. The host adopts
   * the volume's buffer with SetVolume() before its values are there (the
   * page's buffer of zeros), then calls BeginStreaming(): from then on no
   * point is resident, and the full level's pyramid counts no cell (its
   * level-1 tiles are empty). RegionArrived(): the host has written points
   * [first, last] (inclusive, per axis) into the buffer; they go into the
   * texture as a sub-region (HistoPyramidGL::UploadRegion(), a
   * glTexSubImage3D of those texels, not a whole upload), and each tile
   * whose points have all arrived gets its value range. Residency is kept
   * per run of 8 points along each axis, as BlockLODVolume keeps it (a
   * region covers a run only when it covers all of it; the last run of an
   * axis may be shorter). The pyramid is built again only at the next
   * Update(), which a host calls when it draws the full level (the page:
   * once every brick its surfaces need has arrived), so a brick costs its
   * upload and not a build; it then counts exactly the dense volume's cells
   * wherever every point they read has arrived, and nothing elsewhere (no
   * cell of a point still to come). Levels 2 and 1 sample every point and
   * are refused while streaming; level 0 is drawn from the host's samples
   * (SetCoarseSource()). EndStreaming(): every point has arrived (any run
   * the regions did not cover is uploaded then, with the whole texture);
   * the coarse levels are sampled from the volume again. A volume kept as
   * bricks (IsBricked()) does not stream: BeginStreaming() refuses it with
   * the reason (its bricks read the values as they become active).
   */
  bool BeginStreaming(std::string& error);
  bool RegionArrived(const int first[3], const int last[3], std::string& error);
  bool EndStreaming(std::string& error);
  bool IsStreaming() const;
  ///@}

  /**
   * The samples of coarse level `level` (0, 1 or 2) from the host instead of
   * from the volume: `samples` is the volume at that level's stride
   * (LevelStride(level)), its point c standing for the volume's point
   * stride * c (the server's levels sample so, without the last partial
   * layer MakeCoarseCopy() adds), its Data kept valid by the host while the
   * scene holds it. A streaming volume draws its first frames from the
   * server's level 0 this way, before its own values are there. A null Data
   * goes back to sampling the volume. The level's texture and pyramid are
   * made again at its next frame. Forgotten with the volume (a SetVolume()
   * that uploads) and at EndStreaming(). False, with the reason, for a level
   * outside -1..2 or samples of under 2 points on an axis.
   */
  bool SetCoarseSource(int level, const VolumeDescription& samples, std::string& error);

  /**
   * The surfaces `looks` say, as every host draws them: NaN values left out,
   * sorted by value (stably: a repeated value keeps its first look), each
   * value once, the lowest MaximumIsovalues kept; the notes say what was
   * left out and why.
   */
  static SurfaceSelection Normalize(const std::vector<IsosurfaceLook>& looks);

  /// Adopt `looks`, normalised (see Normalize(), whose result it returns).
  SurfaceSelection SetSurfaces(const std::vector<IsosurfaceLook>& looks);
  const std::vector<IsosurfaceLook>& GetSurfaces() const;

  /**
   * Build the pyramid if the surfaces' values or the volume changed since
   * the last build (nothing to build without surfaces). False, with the
   * reason, when there is no volume or the build fails.
   */
  bool Update(std::string& error);

  /// The coarsest volume level: stride 16, one point in 16 along each axis (no Block LOD level).
  static constexpr int CoarsestLevel = -1;

  /// A volume level's stride: LevelStride(level) for Block LOD's levels 0 to 3, 16 for
  /// CoarsestLevel (0 outside CoarsestLevel..3).
  static int VolumeLevelStride(int level);

  /**
   * Update() for a volume level (IsosurfaceFrame::Level): 3 is Update();
   * 2, 1, 0 and -1 sample the volume at VolumeLevelStride(level) (2, 1, 0:
   * the samples of Block LOD's level, the last point of each axis included),
   * upload the samples as the level's own volume texture (once per volume)
   * and build its pyramid when the surfaces' values changed since its last
   * build. False, with the reason, for a level outside -1..3, without a
   * volume, or when the upload or the build fails. Render() calls it for the
   * frame's level.
   */
  bool UpdateLevel(int level, std::string& error);

  /**
   * Update(), then draw the scene's surfaces for `frame` (its Surfaces are
   * ignored) into the bound draw framebuffer with the host's depth function.
   * No surfaces draw nothing. False, with the reason, when the update fails,
   * a program does not build, the context lacks what the frame needs, or a
   * GL call fails.
   */
  bool Render(const IsosurfaceFrame& frame, std::string& error);

  /**
   * The active cell-isovalue pairs of the built pyramid (0 before a build):
   * the primitives the next Render() draws, known after Update() and before
   * the frame, which is when a host chooses its sample distance.
   */
  std::uint64_t GetActivePairs() const;

  /// The active pairs of a level's pyramid, built for the current surfaces (0 when not built).
  std::uint64_t GetActivePairs(int level) const;

  /**
   * The isovalues a level's pyramid was last built for (normalised, as
   * GetSurfaces() holds them; empty before its first build and after a
   * volume upload): a host compares them with the surfaces it is about to
   * draw to know whether a frame at that level must build first, and so
   * predict an isovalue change's first frame (its build) before choosing it.
   */
  std::vector<double> GetBuiltValues(int level) const;

  /// Programs the scene's renderer has compiled so far (0 without a context): a host that
  /// times its frames takes the difference across a frame as that frame's compiled programs.
  std::uint64_t GetProgramBuilds() const;

  /**
   * The programs Render(`frame`) would compile (the isosurface shaders' variant for the frame's
   * level and its passes', IsosurfaceRendererGL::ProgramsToBuild), asked before drawing it, so that
   * a host predicts a frame's one-off work from what is compiled, not from a key of its own. -1
   * where it cannot be known yet: the level is not built for the current surfaces (the variant
   * depends on the isovalues the pyramid counts and on its layout), or the full level is kept as
   * bricks.
   */
  int ProgramsToBuild(const IsosurfaceFrame& frame) const;

  /**
   * A level's active pairs before it is built, from the volume's: a surface
   * crosses about 1 / stride^2 as many cells of stride^3 voxels (at least 1
   * when the volume's are not 0). Hosts predict a coarse level's first frame with it.
   */
  static std::uint64_t EstimateActivePairs(std::uint64_t fullPairs, int level);

  /// The points of a level's samples per axis (every VolumeLevelStride()-th and the last).
  static std::array<int, 3> LevelDimensions(const int points[3], int level);

  /// What the scene did (see IsosurfaceSceneStats).
  const IsosurfaceSceneStats& GetStats() const;

  /// Bytes of GPU memory held now for the volume (its texture and the pyramid, with the coarse
  /// levels made: at most 1/8 + 1/64 + 1/512 + 1/4096 of the volume's).
  std::uint64_t GetGPUMemoryBytes() const;

  /// The volume texture's size in texels for a volume of `points` (4 points to a texel along x).
  static std::array<int, 3> VolumeTextureSize(const int points[3]);
  /// What GetGPUMemoryBytes() will be once a volume of `type` and `points` is uploaded and built.
  static std::uint64_t EstimateGPUMemoryBytes(ScalarType type, const int points[3]);
  /// Bytes of the first-hit pass's buffers (0 until one is drawn).
  std::uint64_t GetFrameBufferBytes() const;

  /// Frees every GL object and forgets the volume and the context (which must be current).
  void Release();

private:
  struct Internals;
  std::unique_ptr<Internals> Impl;
};

} // namespace mediso

#endif
