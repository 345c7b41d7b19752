// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkHistoPyramidIsoMapper
 * @brief   Exact GPU isosurfaces of image data by HistoPyramid cell rasterisation.
 *
 * vtkHistoPyramidIsoMapper renders the isosurfaces of a vtkVolumeProperty
 * (vtkVolumeProperty::GetIsoSurfaceValues(), up to 8) of a single-component
 * vtkImageData as the exact surfaces of the trilinear interpolant, with
 * correct depth, in OpenGL 3.2 core / GLSL 1.50. It implements the GPU path of
 * "Hardware Accelerated Medical Data Visualisation on the Web" (section 4.1),
 * which follows Liu, Clapworthy & Dong, "Fast isosurface rendering on a GPU by
 * cell rasterization" (2009), with the HistoPyramid of Ziegler et al. (2006):
 *
 * -# The volume is uploaded once as a 3D texture that keeps its precision
 *    (int16 stays 16-bit) and kept until the input or its array changes.
 * -# vtkOpenGLHistoPyramid counts the active cells of the current isovalues
 *    (min < iso <= max over the 8 corners, as vtkMarchingCubes) in a 3D 8:1
 *    pyramid built by render-to-texture passes; only the total comes back to
 *    the CPU. It is rebuilt only when the isovalues or the data change:
 *    camera moves reuse it (GetNumberOfPyramidBuilds()).
 * -# One glDrawArrays(GL_POINTS, 0, total) with no vertex attributes draws
 *    every active (cell, isovalue) pair. The vertex stage
 *    (vtkHistoPyramidIso_vs.glsl) walks down the pyramid with gl_VertexID to
 *    its cell, visiting children nearest-first for the current eye, so the
 *    primitives come out front to back with no sort (back to front for
 *    translucency) and, on frames where that provably covers every cell
 *    (the volume beyond the near plane, no cell wider than the largest
 *    point), makes the cell's footprint a point sprite over the bounding
 *    square of the projected box that holds the surface in that cell (the
 *    crossings on its edges and the faces that straddle the isovalue bound
 *    it; often much less than the cell); on other frames (close zooms, the eye
 *    in the volume) the geometry stage (vtkHistoPyramidIso_gs.glsl) emits
 *    the faces of the cell box that face the eye, a footprint that covers the
 *    cell at any zoom in both projections (see AllowPointFootprint,
 *    GetLastFootprint()); the fragment stage
 *    (vtkHistoPyramidIso_fs.glsl) finds the first root of the cubic the
 *    trilinear interpolant makes along the ray, shades it with Phong (the
 *    volume property's ambient, diffuse, specular and specular power, the
 *    renderer's lights) and writes gl_FragDepth (or, in the first-hit
 *    pass of opaque frames, see FirstHitPass, its colour and depth go to
 *    the mapper's own buffers and are composited after).
 * -# Colour and opacity of each isovalue come from the property's colour and
 *    scalar opacity transfer functions at that value, or from colours and
 *    opacities given per surface (SetColorSource()). When all are opaque,
 *    each primitive draws one isovalue, front to back, with depth writes
 *    (in the first-hit pass each cell is one primitive that takes the
 *    nearest hit of its isovalues).
 *    Otherwise every cell is drawn once, back to front, and composites all of
 *    its isovalues' hits in depth order: translucent skin over opaque bone
 *    in one pass, blended over whatever the scene holds.
 * -# The drawing program is compiled per variant (footprint, opaque or
 *    translucent, number of lights): a software rasteriser such as llvmpipe
 *    runs every branch of a fragment shader under SIMD masks, so a mode's
 *    code left in another mode's shader costs every fragment.
 *
 * The volume's matrix (position, orientation, scale), the image's spacing,
 * origin and direction matrix are honoured. Surfaces are always shaded
 * (an unshaded isosurface shows no shape), regardless of
 * vtkVolumeProperty::GetShade().
 *
 * Capability check and fallback: the first render in a window runs
 * vtkMedicalGLCapabilities::Probe(); if the context lacks OpenGL 3.2 or
 * working integer textures, a shader does not build, the volume exceeds
 * GL_MAX_3D_TEXTURE_SIZE, or the pyramid needs more vertex texture units than
 * the context has (or MEDISO_DISABLE_GPU_PATH=1, or ForceCPUFallback is on),
 * the mapper says so once (a warning with the reason) and renders the same
 * isovalues with vtkBlockLODContour (level 3) and a vtkPolyDataMapper
 * (translucent surfaces are then blended unsorted). GetLastRenderPath()
 * tells which path drew the last frame, GetFallbackReason() why.
 *
 * GPU memory: GetGPUMemoryBytes() (the volume texture plus about 0.16 bytes
 * per padded cell for the pyramid) stays the same across isovalue changes;
 * ReleaseGraphicsResources() frees every OpenGL object.
 *
 * Bad input (no scalars, cell scalars, several components, fewer than 2
 * points along an axis, a zero or non-finite spacing, an unsupported type,
 * no isovalues, isovalues that are not numbers) gives one error or warning
 * and nothing drawn, never a crash.
 *
 * @sa vtkOpenGLHistoPyramid vtkMedicalGLCapabilities vtkBlockLODContour
 */
#ifndef vtkHistoPyramidIsoMapper_h
#define vtkHistoPyramidIsoMapper_h

#include "MedicalIsosurfacesMappersModule.h" // For export macro
#include "vtkVolumeMapper.h"

#include <cmath>   // For std::isfinite
#include <cstdint> // For std::uint64_t
#include <memory>  // For std::unique_ptr
#include <sstream> // For std::ostringstream
#include <string>  // For std::string
#include <vector>  // For std::vector

class vtkDataArray;
class vtkImageData;
class vtkOpenGLRenderWindow;

class MEDICALISOSURFACESMAPPERS_EXPORT vtkHistoPyramidIsoMapper : public vtkVolumeMapper
{
public:
  static vtkHistoPyramidIsoMapper* New();
  vtkTypeMacro(vtkHistoPyramidIsoMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Which path drew the last frame.
  enum RenderPathType
  {
    NoPath = 0,      ///< Nothing drawn (no input, bad input, no isovalues, nothing active).
    GPUPath = 1,     ///< HistoPyramid cell rasterisation.
    FallbackPath = 2 ///< vtkBlockLODContour + vtkPolyDataMapper.
  };

  ///@{
  /**
   * The path of the last Render() (a RenderPathType), as a value and as a
   * word ("none", "gpu", "fallback").
   */
  vtkGetMacro(LastRenderPath, int);
  const char* GetLastRenderPathAsString() const;
  ///@}

  /// Why the GPU path is not used (empty while it is).
  const std::string& GetFallbackReason() const { return this->FallbackReason; }

  ///@{
  /**
   * Render through the CPU fallback even when the GPU path works (tests,
   * comparisons). Default off.
   */
  vtkSetMacro(ForceCPUFallback, bool);
  vtkGetMacro(ForceCPUFallback, bool);
  vtkBooleanMacro(ForceCPUFallback, bool);
  ///@}

  /// How the GPU path covers each cell on screen.
  enum FootprintType
  {
    BoxFootprint = 0,  ///< The cell box's front faces, from a geometry shader.
    PointFootprint = 1 ///< One point sprite over the projected bounding square of the surface's box in the cell.
  };

  ///@{
  /**
   * Let the GPU path draw each cell as one point sprite (no geometry shader)
   * on frames where that provably covers every cell: the whole volume lies
   * beyond the near plane and no cell can project to more pixels than
   * GL_POINT_SIZE_RANGE allows. Other frames (close zooms, the eye in or near
   * the volume) draw the cell box's front faces. Both footprints feed the
   * same ray casting, so they give the same image; points are much cheaper
   * where primitives are costly (software rasterisers). Default on.
   */
  vtkSetMacro(AllowPointFootprint, bool);
  vtkGetMacro(AllowPointFootprint, bool);
  vtkBooleanMacro(AllowPointFootprint, bool);
  ///@}

  ///@{
  /// The footprint of the last GPU frame (a FootprintType; "boxes" or "points").
  vtkGetMacro(LastFootprint, int);
  const char* GetLastFootprintAsString() const;
  ///@}

  ///@{
  /**
   * Draw opaque frames with point footprints in two passes (default on):
   * the cells into the mapper's own buffers, where the depth test keeps
   * only the first hit of each pixel in drawing order, then that colour and
   * exact depth into the scene with the scene's depth test. The cells come
   * out front to back, so the first hit in drawing order is the nearest, and
   * the depth test runs before the fragment stage: a fragment behind a
   * surface already found costs no ray cast. With several (opaque)
   * isovalues each cell is one primitive that takes the nearest hit of its
   * isovalues. In one pass the fragment stage writes gl_FragDepth, which
   * makes many rasterisers (llvmpipe always; GPUs without
   * GL_ARB_conservative_depth) test depth only after it. The image is the
   * same; the buffers cost 10 bytes per pixel of the rectangle the volume's
   * box projects to (cut to the viewport, rounded up to 64 pixels; kept
   * while the projection fits, remade when it outgrows them or shrinks
   * below a quarter of them; GetFrameBufferBytes()). Off: always one pass.
   */
  vtkSetMacro(FirstHitPass, bool);
  vtkGetMacro(FirstHitPass, bool);
  vtkBooleanMacro(FirstHitPass, bool);
  ///@}

  /// Whether the last GPU frame drew through the first-hit pass.
  vtkGetMacro(LastFirstHitPass, bool);

  /// Primitives (active cell-isovalue pairs) of the last GPU frame.
  vtkGetMacro(NumberOfPrimitives, std::uint64_t);

  /// Seconds the last pyramid build took (its passes and the read-back of the total).
  vtkGetMacro(LastBuildSeconds, double);

  ///@{
  /**
   * The last pyramid build's level-1 pass: how many of its tiles it drew
   * (those whose value range holds an isovalue; see vtkOpenGLHistoPyramid)
   * and how many there are.
   */
  vtkGetMacro(LastBuildTilesDrawn, std::uint64_t);
  vtkGetMacro(LastBuildTiles, std::uint64_t);
  ///@}

  /// Pyramid builds and volume uploads so far (camera moves do neither).
  vtkGetMacro(NumberOfPyramidBuilds, std::uint64_t);
  vtkGetMacro(NumberOfVolumeUploads, std::uint64_t);

  /// Bytes of GPU memory the mapper holds now for the volume (volume and pyramid).
  std::uint64_t GetGPUMemoryBytes() const;

  /// Bytes of the first-hit pass's buffers (0 until one is drawn; see SetFirstHitPass).
  std::uint64_t GetFrameBufferBytes() const;

  /// Triangles of the last fallback frame (0 on the GPU path).
  vtkGetMacro(NumberOfFallbackTriangles, std::uint64_t);

  /// Where each isovalue's colour and opacity come from (see SetColorSource()).
  enum ColorSourceType
  {
    TransferFunctionColors = 0, ///< The property's colour and scalar opacity functions at the value.
    SolidColors = 1,            ///< SolidColor for every isovalue.
    SurfaceColors = 2           ///< SurfaceColor(i) for the i-th isovalue.
  };

  ///@{
  /**
   * The colour of each isosurface: from the vtkVolumeProperty's colour
   * transfer function at the isovalue and its opacity multiplied by the
   * scalar opacity function there (TransferFunctionColors, the default), one
   * SolidColor for all (SolidColors), or SurfaceColor(i) for the i-th value
   * of vtkVolumeProperty::GetIsoSurfaceValues(), in the order given there
   * (SurfaceColors; values past the colours set take SolidColor). Whatever
   * the source, surface i's opacity is further multiplied by
   * SurfaceOpacity(i) (1 where none is set) and by Opacity: an application
   * can give each surface its own colour and opacity without editing
   * transfer functions. A surface of opacity 0 is not drawn.
   */
  vtkSetClampMacro(ColorSource, int, TransferFunctionColors, SurfaceColors);
  vtkGetMacro(ColorSource, int);
  vtkSetVector3Macro(SolidColor, double);
  vtkGetVector3Macro(SolidColor, double);
  void SetNumberOfSurfaceColors(int number);
  int GetNumberOfSurfaceColors() const { return static_cast<int>(this->SurfaceColorValues.size() / 3); }
  void SetSurfaceColor(int i, double r, double g, double b);
  void SetNumberOfSurfaceOpacities(int number);
  int GetNumberOfSurfaceOpacities() const { return static_cast<int>(this->SurfaceOpacityValues.size()); }
  void SetSurfaceOpacity(int i, double opacity);
  vtkSetClampMacro(Opacity, double, 0.0, 1.0);
  vtkGetMacro(Opacity, double);
  ///@}

  /**
   * Why an image of this spacing holds no surface (a zero or non-finite
   * component: its points would not be apart along that axis), as the
   * message Render() gives for it; empty when the spacing is fine.
   */
  static std::string CheckSpacing(const double spacing[3]);

  void Render(vtkRenderer* ren, vtkVolume* vol) override;
  void ReleaseGraphicsResources(vtkWindow* win) override;

protected:
  vtkHistoPyramidIsoMapper();
  ~vtkHistoPyramidIsoMapper() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;

private:
  vtkHistoPyramidIsoMapper(const vtkHistoPyramidIsoMapper&) = delete;
  void operator=(const vtkHistoPyramidIsoMapper&) = delete;

  int LastRenderPath = NoPath;
  std::string FallbackReason;
  bool ForceCPUFallback = false;
  bool AllowPointFootprint = true;
  int LastFootprint = BoxFootprint;
  bool FirstHitPass = true;
  bool LastFirstHitPass = false;
  std::uint64_t NumberOfPrimitives = 0;
  std::uint64_t NumberOfPyramidBuilds = 0;
  double LastBuildSeconds = 0.0;
  std::uint64_t LastBuildTilesDrawn = 0;
  std::uint64_t LastBuildTiles = 0;
  std::uint64_t NumberOfVolumeUploads = 0;
  std::uint64_t NumberOfFallbackTriangles = 0;
  int ColorSource = TransferFunctionColors;
  double SolidColor[3] = { 1.0, 1.0, 1.0 };
  std::vector<double> SurfaceColorValues;   // r, g, b per surface
  std::vector<double> SurfaceOpacityValues; // one per surface
  double Opacity = 1.0;

  struct Surface; // one isovalue and its colour and opacity
  bool RenderGPU(vtkRenderer* ren, vtkVolume* vol, vtkImageData* image, vtkDataArray* scalars,
    const std::vector<Surface>& surfaces, std::string& reason);
  bool PrepareFirstHit(
    vtkOpenGLRenderWindow* renWin, int rectWidth, int rectHeight, const int viewport[4]);
  bool CompositeFirstHit(vtkOpenGLRenderWindow* renWin, std::string& reason);
  void RenderFallback(vtkRenderer* ren, vtkVolume* vol, vtkImageData* image,
    vtkDataArray* scalars, const std::vector<Surface>& surfaces);

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

//------------------------------------------------------------------------------
inline std::string vtkHistoPyramidIsoMapper::CheckSpacing(const double spacing[3])
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(spacing[a]) || spacing[a] == 0.0)
    {
      std::ostringstream msg;
      msg << "the image's spacing (" << spacing[0] << ", " << spacing[1] << ", " << spacing[2]
          << ") has a zero or non-finite component: the points of a volume need a non-zero, "
             "finite distance along every axis; nothing is drawn.";
      return msg.str();
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetNumberOfSurfaceColors(int number)
{
  const std::size_t size = 3 * static_cast<std::size_t>(number > 0 ? number : 0);
  if (size != this->SurfaceColorValues.size())
  {
    this->SurfaceColorValues.resize(size, 1.0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetSurfaceColor(int i, double r, double g, double b)
{
  if (i < 0)
  {
    return;
  }
  if (static_cast<std::size_t>(i) >= this->SurfaceColorValues.size() / 3)
  {
    this->SetNumberOfSurfaceColors(i + 1);
  }
  double* color = &this->SurfaceColorValues[3 * static_cast<std::size_t>(i)];
  if (color[0] != r || color[1] != g || color[2] != b)
  {
    color[0] = r;
    color[1] = g;
    color[2] = b;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetNumberOfSurfaceOpacities(int number)
{
  const std::size_t size = static_cast<std::size_t>(number > 0 ? number : 0);
  if (size != this->SurfaceOpacityValues.size())
  {
    this->SurfaceOpacityValues.resize(size, 1.0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetSurfaceOpacity(int i, double opacity)
{
  if (i < 0)
  {
    return;
  }
  if (static_cast<std::size_t>(i) >= this->SurfaceOpacityValues.size())
  {
    this->SetNumberOfSurfaceOpacities(i + 1);
  }
  if (this->SurfaceOpacityValues[static_cast<std::size_t>(i)] != opacity)
  {
    this->SurfaceOpacityValues[static_cast<std::size_t>(i)] = opacity;
    this->Modified();
  }
}

#endif
