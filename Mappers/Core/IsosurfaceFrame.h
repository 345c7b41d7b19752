// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file IsosurfaceFrame.h
 * @brief What one frame of isosurfaces shows, and from where (no GL, no VTK).
 *
 * The hosts of the GPU core (the ParaView mapper's shell, mediso-render, the
 * web page) describe a frame with these plain structures: the surfaces'
 * looks, the volume's cell-index space seen by a camera, the lights and the
 * material. IsosurfaceScene draws it; the web page's mesh renderer shades
 * its triangles with the same lights and material. IsosurfaceSceneStats is
 * what the scene says it did, which the hosts forward whole (the VTK mapper
 * and the ParaView representation, the program's --stats, the page's stats()).
 */
#ifndef MedicalIsosurfaces_IsosurfaceFrame_h
#define MedicalIsosurfaces_IsosurfaceFrame_h

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace mediso
{

/// Most lights a frame takes.
constexpr int MaximumLights = 6;

/// Most clipping planes a frame takes: VTK's six clipping planes and the six
/// faces of a cropping box.
constexpr int MaximumClipPlanes = 12;

/**
 * Whether the first-hit pass drops hidden points (IsosurfaceRendererGL::SetHitCull(),
 * IsosurfaceScene::SetHitCull()): Auto where the context is a hardware one (the GL renderer
 * string names no software rasteriser, and the context is no WebGL one, whose renderer string
 * the browser hides), On and Off whatever it is. The image is the same either way.
 */
enum class HitCull
{
  Auto,
  On,
  Off
};

/// One isosurface: its value, colour and opacity (0 < opacity <= 1).
struct IsosurfaceLook
{
  double Value = 0.0;
  float Color[3] = { 1.0f, 1.0f, 1.0f };
  float Opacity = 1.0f;
};

/// What a frame draws, and from where. Matrices are row-major, column vectors (VTK's convention).
struct IsosurfaceFrame
{
  /// Cell-index space (point (i, j, k) of the volume at (i, j, k)) to the camera's view space.
  double IndexToView[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  /// View space to clip space (OpenGL's convention: the camera looks down -z).
  double Projection[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  bool Parallel = false;
  /// Distance from the eye to the near clipping plane (view space).
  double NearPlane = 0.01;
  /// The viewport in the bound framebuffer's pixels (x, y, width, height).
  int Viewport[4] = { 0, 0, 1, 1 };
  /// The isosurfaces, exactly those the pyramid was last built for, in the same order
  /// (IsosurfaceScene fills them in from its own list).
  std::vector<IsosurfaceLook> Surfaces;
  /// Lights: directions towards the light in view space, and colours (times intensity).
  int NumberOfLights = 0;
  float LightDirections[MaximumLights][3] = {};
  float LightColors[MaximumLights][3] = {};
  float Ambient = 0.1f;
  float Diffuse = 0.7f;
  float Specular = 0.2f;
  float SpecularPower = 10.0f;
  /// Let the renderer draw point sprites where they provably cover every cell.
  bool AllowPointFootprint = true;
  /// Draw opaque frames with point footprints through the first-hit pass.
  bool FirstHitPass = true;
  /// Clipping planes in cell-index space, at most MaximumClipPlanes: plane (a, b, c, d)
  /// keeps the points where a i + b j + c k + d >= 0. The kept part of the volume is the
  /// intersection of the planes' kept half-spaces (convex), so each ray meets it in one
  /// interval: the surfaces are cut exactly at the planes and left open there, and a
  /// surface behind a removed one shows through. A cropping box is six of them.
  std::vector<std::array<double, 4>> ClipPlanes;
  /// Image sample distance: above 1, the surfaces are drawn into a target of
  /// Viewport / SampleDistance pixels (rounded up), then up to the viewport with their
  /// depth (interactive frames: about 1 / SampleDistance^2 of the fragment work). 1 (or
  /// anything not above 1) draws every pixel, the full-quality image.
  float SampleDistance = 1.0f;
  /// The volume level drawn: 3 the volume itself; 2, 1 or 0 its samples at Block LOD's strides
  /// 2, 4 or 8 (BlockLOD.h's LevelStride(), the samples of vtkBlockLODContour's levels), a
  /// coarse volume with its own pyramid that IsosurfaceScene makes on the level's first frame
  /// (interactive frames: about 1 / stride^2 of the primitives); -1 the samples at stride 16,
  /// the GPU path's own (IsosurfaceScene::CoarsestLevel). Its cells are drawn
  /// stride times larger, so the frame shows the exact trilinear surface of the coarse volume
  /// where the level's cells are (see IsosurfaceScene::UpdateLevel()).
  int Level = 3;

  /// The lights a program draws with (NumberOfLights within 0..MaximumLights): its
  /// MEDISO_LIGHTS, a constant of the program, since a software rasteriser runs every
  /// iteration of a loop with a uniform bound for every fragment.
  int LightsUsed() const { return std::max(0, std::min(this->NumberOfLights, MaximumLights)); }
};

/// What IsosurfaceScene did: its last frame, its last pyramid build and volume upload, and its work
/// so far.
struct IsosurfaceSceneStats
{
  ///@{
  /// The last frame: the primitives (active cell-isovalue pairs) it drew, whether as point
  /// sprites (else quads over each cell's box) and through the first-hit pass.
  std::uint64_t Primitives = 0;
  bool PointFootprint = false;
  bool FirstHit = false;
  ///@}

  /// The last frame's first-hit pass dropped hidden points (see HitCull).
  bool HitCull = false;

  /// The image sample distance the last frame was drawn at (1: every pixel; see
  /// IsosurfaceFrame::SampleDistance).
  float SampleDistance = 1.0f;

  /// The volume level the last frame was drawn at (3: the volume; see IsosurfaceFrame::Level).
  int Level = 3;

  ///@{
  /// The last pyramid build: seconds (its passes and the read-back of the total), the level-1
  /// tiles it drew (those whose value range holds an isovalue) and the volume's tiles.
  double BuildSeconds = 0.0;
  std::uint64_t BuildTilesDrawn = 0;
  std::uint64_t BuildTiles = 0;
  ///@}

  /// Seconds the last volume upload took (packing, tile ranges, the 3D texture).
  double UploadSeconds = 0.0;

  ///@{
  /// Pyramid builds and volume uploads so far (camera moves do neither).
  std::uint64_t PyramidBuilds = 0;
  std::uint64_t VolumeUploads = 0;
  ///@}

  /// Regions of a streaming volume uploaded so far (IsosurfaceScene::RegionArrived(): each a
  /// sub-region of the texture, not a whole upload).
  std::uint64_t RegionUploads = 0;

  /// Builds of a coarse level's pyramid so far (IsosurfaceFrame::Level below 3), the level's
  /// sampling and upload included when it was the level's first.
  std::uint64_t CoarseBuilds = 0;
  ///@{
  /// A volume kept as bricks (IsosurfaceScene: over the texture limit or the GPU budget; none
  /// for a volume in one texture): the brick edge in points, the bricks, those the last build's
  /// isovalues cross, those resident on the GPU, and brick uploads so far. OverBudget: the last
  /// build's active bricks alone exceed the GPU budget (its reason says so; hosts fall back).
  int BrickPoints = 0;
  std::uint64_t Bricks = 0;
  std::uint64_t ActiveBricks = 0;
  std::uint64_t ResidentBricks = 0;
  std::uint64_t BrickUploads = 0;
  bool OverBudget = false;
  ///@}
  ///@{
  /// The brick pool (IsosurfaceScene::SetBrickPool()): its slots (0: none, the bricks drawn as
  /// their own pyramids), and the pyramids the last build of a bricked volume built (1 with the
  /// pool; without, one per active brick less those kept: a brick that the same of the old and
  /// the new isovalues cross keeps its pyramid, whose counts they do not change).
  std::uint64_t PoolSlots = 0;
  std::uint64_t BrickPyramidBuilds = 0;
  ///@}
};

} // namespace mediso

#endif
