// SPDX-License-Identifier: BSD-3-Clause
#include "vtkHistoPyramidIsoMapper.h"

#include "vtkActor.h"
#include "vtkBlockLODContour.h"
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkDataArray.h"
#include "vtkDepthSortPolyData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMatrix3x3.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkMedicalGLCapabilities.h"
#include "vtkMedicalGLUtilities.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLHistoPyramid.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkOpenGLVertexArrayObject.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtkTimerLog.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkHistoPyramidComposite_fs.h"
#include "vtkHistoPyramidIso_fs.h"
#include "vtkHistoPyramidIso_gs.h"
#include "vtkHistoPyramidIso_vs.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkHistoPyramidIsoMapper);

namespace
{
using namespace medical_gl;

constexpr int MaximumNumberOfLights = 6;

// Uploads a matrix given in VTK's row-major, column-vector convention.
void SetMatrix4(vtkShaderProgram* program, const char* name, const vtkMatrix4x4* m)
{
  const GLint location = program->FindUniform(name);
  if (location >= 0)
  {
    GLfloat values[16];
    for (int i = 0; i < 16; ++i)
    {
      values[i] = static_cast<GLfloat>(m->GetData()[i]);
    }
    glUniformMatrix4fv(location, 1, GL_TRUE, values);
  }
}

void SetMatrix3(vtkShaderProgram* program, const char* name, const double m[9])
{
  const GLint location = program->FindUniform(name);
  if (location >= 0)
  {
    GLfloat values[9];
    for (int i = 0; i < 9; ++i)
    {
      values[i] = static_cast<GLfloat>(m[i]);
    }
    glUniformMatrix3fv(location, 1, GL_TRUE, values);
  }
}

// Whether point sprites cover every cell this frame (see the vertex shader):
// the index box [0, cells] lies wholly beyond the near plane, and no cell can
// project to more than maxPointSize - 3 pixels. The bound on a cell's
// projected extent: with d >= dmin the depth of every point of the volume and
// L the longest cell diagonal in view space, two points of a cell differ in
// x/d by at most L/dmin (1 + |x/d|), and |x/d| <= (1 + |P02|)/|P00| on screen
// (NDC x = P00 x/d - P02 in perspective; NDC x = P00 x + P03 in parallel).
bool PointsCoverCells(vtkMatrix4x4* indexToView, vtkMatrix4x4* projection,
  const int cells[3], double nearPlane, bool parallel, const int viewport[4], float maxPointSize)
{
  double dmin = VTK_DOUBLE_MAX;
  for (int i = 0; i < 8; ++i)
  {
    const double p[4] = { (i & 1) ? double(cells[0]) : 0.0, (i & 2) ? double(cells[1]) : 0.0,
      (i & 4) ? double(cells[2]) : 0.0, 1.0 };
    double v[4];
    indexToView->MultiplyPoint(p, v);
    dmin = std::min(dmin, -v[2]); // the camera looks down -z
  }
  if (!(dmin > nearPlane * 1.0001 && dmin > 0.0))
  {
    return false;
  }
  double diagonal = 0.0;
  for (int i = 0; i < 4; ++i)
  {
    const double d[3] = { (i & 1) ? -1.0 : 1.0, (i & 2) ? -1.0 : 1.0, 1.0 };
    double v[3] = { 0.0, 0.0, 0.0 };
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        v[r] += indexToView->GetElement(r, c) * d[c];
      }
    }
    diagonal = std::max(diagonal, vtkMath::Norm(v));
  }
  const double p00 = std::abs(projection->GetElement(0, 0));
  const double p11 = std::abs(projection->GetElement(1, 1));
  double ndcX, ndcY; // largest NDC extent of a cell
  if (parallel)
  {
    ndcX = diagonal * p00;
    ndcY = diagonal * p11;
  }
  else
  {
    ndcX = diagonal / dmin * (p00 + 1.0 + std::abs(projection->GetElement(0, 2)));
    ndcY = diagonal / dmin * (p11 + 1.0 + std::abs(projection->GetElement(1, 2)));
  }
  const double pixels = std::max(0.5 * ndcX * viewport[2], 0.5 * ndcY * viewport[3]);
  return pixels + 3.0 <= maxPointSize;
}

// The window pixels the volume can cover: the bounding rectangle of the
// index box [0, cells]'s 8 projected corners (x, y, width, height), widened by
// a pixel on every side and cut to the viewport (at least 1x1). Only for a box
// wholly in front of the eye (as point footprints require; see
// PointsCoverCells), where the projected corners bound the box's projection.
void ProjectedRectangle(
  vtkMatrix4x4* indexToClip, const int cells[3], const int viewport[4], int rect[4])
{
  double lo[2] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX };
  double hi[2] = { -VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };
  for (int i = 0; i < 8; ++i)
  {
    const double p[4] = { (i & 1) ? double(cells[0]) : 0.0, (i & 2) ? double(cells[1]) : 0.0,
      (i & 4) ? double(cells[2]) : 0.0, 1.0 };
    double clip[4];
    indexToClip->MultiplyPoint(p, clip);
    for (int a = 0; a < 2; ++a)
    {
      const double window = viewport[a] + 0.5 * (clip[a] / clip[3] + 1.0) * viewport[2 + a];
      lo[a] = std::min(lo[a], window);
      hi[a] = std::max(hi[a], window);
    }
  }
  for (int a = 0; a < 2; ++a)
  {
    const double first = std::max(std::floor(lo[a]) - 1.0, double(viewport[a]));
    const double last = std::min(std::ceil(hi[a]) + 1.0, double(viewport[a] + viewport[2 + a]));
    const int begin = std::min(static_cast<int>(first), viewport[a] + viewport[2 + a] - 1);
    rect[a] = begin;
    rect[2 + a] = std::max(static_cast<int>(last) - begin, 1);
  }
}

bool SupportedType(int type)
{
  switch (type)
  {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
    case VTK_UNSIGNED_CHAR:
    case VTK_SHORT:
    case VTK_UNSIGNED_SHORT:
    case VTK_INT:
    case VTK_UNSIGNED_INT:
    case VTK_FLOAT:
    case VTK_DOUBLE:
      return true;
    default:
      return false;
  }
}
} // anonymous namespace

//------------------------------------------------------------------------------
// One isovalue to draw and its look.
struct vtkHistoPyramidIsoMapper::Surface
{
  double Value;
  double Color[3];
  double Opacity;
};

//------------------------------------------------------------------------------
struct vtkHistoPyramidIsoMapper::Internals
{
  // GPU path, all in the context of Window.
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  vtkNew<vtkOpenGLHistoPyramid> Pyramid;
  vtkNew<vtkOpenGLVertexArrayObject> VAO;
  bool Probed = false;
  bool GPUUsable = false;
  std::string GPUReason;
  int MaxVertexTextureUnits = 0;
  float MaxPointSize = 1.0f;
  float PointSizeGranularity = 0.0f;
  bool ConservativeDepth = false;
  int Max3DTextureSize = 0;

  // What the uploaded volume and the built pyramid were made from.
  vtkDataArray* UploadedArray = nullptr;
  vtkMTimeType UploadedArrayTime = 0;
  int UploadedDims[3] = { 0, 0, 0 };
  std::vector<double> BuiltIsovalues;
  bool PyramidValid = false;

  // The drawing programs of the current pyramid layout, one per variant,
  // keyed by the variant's #defines (footprint, opaque or translucent,
  // number of lights and of translucent isovalues: see RenderGPU), each with
  // the layout key it was built for.
  std::map<std::string, std::pair<std::string, vtkShaderProgram*>> Programs;

  // First-hit pass (see vtkHistoPyramidIsoMapper::SetFirstHitPass): the
  // buffers the cells are drawn into (over the volume's projected rectangle,
  // HitRect), and the program that composites them into the scene.
  vtkSmartPointer<vtkOpenGLFramebufferObject> HitFBO;
  vtkSmartPointer<vtkTextureObject> HitColor; // RGBA8: colour, alpha 1 where hit
  vtkSmartPointer<vtkTextureObject> HitDepth; // R32F: the hit's window depth
  vtkSmartPointer<vtkTextureObject> HitFlag;  // 16-bit depth: a hit is there
  int HitSize[2] = { 0, 0 }; // the buffers' size
  int HitRect[4] = { 0, 0, 0, 0 }; // the window pixels they hold this frame (x, y, w, h)
  std::unique_ptr<vtkOpenGLQuadHelper> Composite;

  void ReleaseHitBuffers(vtkWindow* win)
  {
    for (vtkTextureObject* texture : { this->HitColor.Get(), this->HitDepth.Get(), this->HitFlag.Get() })
    {
      if (texture)
      {
        texture->ReleaseGraphicsResources(win);
      }
    }
    if (this->HitFBO)
    {
      this->HitFBO->ReleaseGraphicsResources(win);
    }
    this->HitColor = nullptr;
    this->HitDepth = nullptr;
    this->HitFlag = nullptr;
    this->HitFBO = nullptr;
    this->HitSize[0] = this->HitSize[1] = 0;
  }

  void ReleaseFirstHit(vtkWindow* win)
  {
    this->ReleaseHitBuffers(win);
    if (this->Composite)
    {
      this->Composite->ReleaseGraphicsResources(win);
    }
    this->Composite.reset();
  }

  // Fallback path.
  vtkNew<vtkBlockLODContour> Contour;
  vtkNew<vtkImageData> IndexImage;
  vtkNew<vtkPolyData> Colored;
  vtkMTimeType ColoredSurfaceTime = 0; // Colored was made from this surface
  std::vector<double> ColoredLooks;    // and these values, colours, opacities
  // Translucent surfaces: the triangles sorted back to front for the current
  // camera (blending in drawing order is only right in that order; the
  // renderer's depth peeling does not reach geometry that a volume mapper
  // draws).
  vtkNew<vtkDepthSortPolyData> Sort;
  vtkNew<vtkPolyDataMapper> PolyMapper;
  vtkNew<vtkActor> Actor;
  vtkNew<vtkMatrix4x4> ActorMatrix;

  // Messages already given (each is said once).
  std::set<std::string> Said;

  void InvalidateGPU()
  {
    this->UploadedArray = nullptr;
    this->UploadedArrayTime = 0;
    this->UploadedDims[0] = this->UploadedDims[1] = this->UploadedDims[2] = 0;
    this->BuiltIsovalues.clear();
    this->PyramidValid = false;
    this->Programs.clear();
  }

  void ReleaseGPU(vtkWindow* win)
  {
    this->Pyramid->ReleaseGraphicsResources(win);
    this->VAO->ReleaseGraphicsResources();
    for (auto& entry : this->Programs)
    {
      if (entry.second.second)
      {
        entry.second.second->ReleaseGraphicsResources(win);
      }
    }
    this->ReleaseFirstHit(win);
    this->InvalidateGPU();
    this->Window = nullptr;
    this->Probed = false;
  }
};

//------------------------------------------------------------------------------
vtkHistoPyramidIsoMapper::vtkHistoPyramidIsoMapper()
  : Impl(new Internals)
{
  Internals& impl = *this->Impl;
  impl.Contour->SetLOD(3);
  impl.Contour->SetComputeNormals(true);
  impl.Contour->SetComputeScalars(true);
  impl.Sort->SetInputData(impl.Colored);
  impl.Sort->SetDirectionToBackToFront();
  impl.Sort->SetDepthSortModeToParametricCenter();
  impl.Sort->SortScalarsOff();
  impl.Sort->SetProp3D(impl.Actor);
  impl.PolyMapper->SetInputData(impl.Colored);
  impl.PolyMapper->SetColorModeToDirectScalars();
  impl.PolyMapper->SetScalarModeToUsePointData();
  impl.PolyMapper->ScalarVisibilityOn();
  impl.Actor->SetMapper(impl.PolyMapper);
  impl.Actor->SetUserMatrix(impl.ActorMatrix);
}

//------------------------------------------------------------------------------
vtkHistoPyramidIsoMapper::~vtkHistoPyramidIsoMapper()
{
  if (this->Impl->Window)
  {
    ScopedContext context(this->Impl->Window);
    this->Impl->ReleaseGPU(this->Impl->Window);
  }
}

//------------------------------------------------------------------------------
int vtkHistoPyramidIsoMapper::FillInputPortInformation(int vtkNotUsed(port), vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoMapper::GetLastFootprintAsString() const
{
  return this->LastFootprint == PointFootprint ? "points" : "boxes";
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoMapper::GetLastRenderPathAsString() const
{
  switch (this->LastRenderPath)
  {
    case GPUPath:
      return "gpu";
    case FallbackPath:
      return "fallback";
    default:
      return "none";
  }
}

//------------------------------------------------------------------------------
std::uint64_t vtkHistoPyramidIsoMapper::GetGPUMemoryBytes() const
{
  return this->Impl->Pyramid->GetGPUMemoryBytes();
}

//------------------------------------------------------------------------------
std::uint64_t vtkHistoPyramidIsoMapper::GetFrameBufferBytes() const
{
  // RGBA8 colour, R32F depth, 16-bit depth buffer.
  return static_cast<std::uint64_t>(this->Impl->HitSize[0]) * this->Impl->HitSize[1] * 10u;
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::ReleaseGraphicsResources(vtkWindow* win)
{
  Internals& impl = *this->Impl;
  // The GPU objects live in the context of the window they were made in; a
  // call for another window (a prop shown in several views) leaves them.
  if (!impl.Window || win == impl.Window)
  {
    if (impl.Window)
    {
      ScopedContext context(impl.Window);
      impl.ReleaseGPU(impl.Window);
    }
    else
    {
      impl.ReleaseGPU(win);
    }
  }
  impl.PolyMapper->ReleaseGraphicsResources(win);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  Internals& impl = *this->Impl;
  this->LastRenderPath = NoPath;
  this->NumberOfPrimitives = 0;
  this->NumberOfFallbackTriangles = 0;

  // Say a message once (per distinct text), as an error or a warning.
  auto sayOnce = [&](bool error, const std::string& text)
  {
    if (impl.Said.insert(text).second)
    {
      if (error)
      {
        vtkErrorMacro(<< text);
      }
      else
      {
        vtkWarningMacro(<< text);
      }
    }
  };

  // 1. The input. No input at all is normal (a ParaView rank without data).
  vtkImageData* image = vtkImageData::SafeDownCast(this->GetInputDataObject(0, 0));
  if (!image || !vol || !ren)
  {
    return;
  }
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
  {
    std::ostringstream msg;
    msg << "needs 3D image data (at least 2 points along every axis), not " << dims[0] << "x"
        << dims[1] << "x" << dims[2] << "; nothing is drawn.";
    sayOnce(true, msg.str());
    return;
  }
  const std::string spacingProblem = CheckSpacing(image->GetSpacing());
  if (!spacingProblem.empty())
  {
    sayOnce(true, spacingProblem);
    return;
  }
  int cellFlag = 0;
  vtkDataArray* scalars = vtkDataArray::SafeDownCast(this->GetScalars(
    image, this->ScalarMode, this->ArrayAccessMode, this->ArrayId, this->ArrayName, cellFlag));
  if (!scalars)
  {
    sayOnce(true, "the input has no point scalars to contour; nothing is drawn.");
    return;
  }
  if (cellFlag)
  {
    sayOnce(true,
      std::string("array '") + (scalars->GetName() ? scalars->GetName() : "") +
        "' is cell data; isosurfaces need point data (apply Cell Data to Point Data first); "
        "nothing is drawn.");
    return;
  }
  if (scalars->GetNumberOfComponents() != 1 || !SupportedType(scalars->GetDataType()))
  {
    std::ostringstream msg;
    msg << "array '" << (scalars->GetName() ? scalars->GetName() : "") << "' has "
        << scalars->GetNumberOfComponents() << " components of type "
        << scalars->GetDataTypeAsString()
        << "; one component of an 8, 16 or 32-bit integer, float or double type is needed; "
           "nothing is drawn.";
    sayOnce(true, msg.str());
    return;
  }

  // 2. The isovalues and their looks, in increasing order; invisible ones
  //    (opacity 0) and NaN ones left out. A value's index in the property's
  //    list picks its surface colour and opacity.
  vtkVolumeProperty* property = vol->GetProperty();
  vtkContourValues* values = property->GetIsoSurfaceValues();
  std::vector<std::pair<double, int>> requested; // value, index in the property's list
  int notANumber = 0;
  for (int i = 0; values && i < values->GetNumberOfContours(); ++i)
  {
    const double v = values->GetValue(i);
    if (std::isnan(v))
    {
      ++notANumber;
    }
    else
    {
      requested.emplace_back(v, i);
    }
  }
  if (notANumber > 0)
  {
    std::ostringstream msg;
    msg << notANumber << " of the " << values->GetNumberOfContours()
        << " isovalues " << (notANumber == 1 ? "is" : "are")
        << " not a number (NaN): an isosurface needs a numeric value; "
        << (requested.empty() ? "nothing is drawn." : "the others are drawn.");
    sayOnce(false, msg.str());
  }
  std::stable_sort(requested.begin(), requested.end(),
    [](const std::pair<double, int>& a, const std::pair<double, int>& b) { return a.first < b.first; });
  requested.erase(std::unique(requested.begin(), requested.end(),
                    [](const std::pair<double, int>& a, const std::pair<double, int>& b)
                    { return a.first == b.first; }),
    requested.end());
  if (requested.empty())
  {
    if (notANumber == 0)
    {
      sayOnce(false,
        "no isovalues: set them with vtkVolumeProperty::GetIsoSurfaceValues() "
        "(ParaView: the representation's Isosurfaces); nothing is drawn.");
    }
    return;
  }
  if (requested.size() > static_cast<std::size_t>(vtkOpenGLHistoPyramid::MaximumNumberOfIsovalues))
  {
    std::ostringstream msg;
    msg << requested.size() << " isovalues requested; only the lowest "
        << vtkOpenGLHistoPyramid::MaximumNumberOfIsovalues << " are drawn.";
    sayOnce(false, msg.str());
    requested.resize(vtkOpenGLHistoPyramid::MaximumNumberOfIsovalues);
  }
  std::vector<Surface> surfaces;
  vtkPiecewiseFunction* opacity = property->GetScalarOpacity(0);
  for (const auto& entry : requested)
  {
    const double v = entry.first;
    const std::size_t index = static_cast<std::size_t>(entry.second);
    Surface s;
    s.Value = v;
    s.Opacity = 1.0;
    if (this->ColorSource == TransferFunctionColors)
    {
      if (property->GetColorChannels(0) == 1)
      {
        const double gray = property->GetGrayTransferFunction(0)->GetValue(v);
        s.Color[0] = s.Color[1] = s.Color[2] = gray;
      }
      else
      {
        property->GetRGBTransferFunction(0)->GetColor(v, s.Color);
      }
      s.Opacity = opacity ? opacity->GetValue(v) : 1.0;
    }
    else if (this->ColorSource == SurfaceColors && 3 * index < this->SurfaceColorValues.size())
    {
      std::copy_n(&this->SurfaceColorValues[3 * index], 3, s.Color);
    }
    else
    {
      std::copy_n(this->SolidColor, 3, s.Color);
    }
    if (index < this->SurfaceOpacityValues.size())
    {
      s.Opacity *= this->SurfaceOpacityValues[index];
    }
    s.Opacity = std::min(1.0, std::max(0.0, s.Opacity * this->Opacity));
    if (s.Opacity > 0.0)
    {
      surfaces.push_back(s);
    }
  }
  if (surfaces.empty())
  {
    this->LastRenderPath = NoPath;
    return;
  }

  // 3. The GPU path, or the fallback when it cannot run.
  auto* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  std::string reason;
  if (this->ForceCPUFallback)
  {
    reason = "ForceCPUFallback is on";
  }
  else if (!renWin)
  {
    reason = "the render window is not an OpenGL window";
  }
  else if (this->RenderGPU(ren, vol, image, scalars, surfaces, reason))
  {
    this->LastRenderPath = GPUPath;
    this->FallbackReason.clear();
    return;
  }
  if (!this->ForceCPUFallback)
  {
    sayOnce(false,
      "GPU isosurface path unavailable (" + reason +
        "); rendering with vtkBlockLODContour and vtkPolyDataMapper instead.");
  }
  this->FallbackReason = reason;
  this->RenderFallback(ren, vol, image, scalars, surfaces);
  this->LastRenderPath = FallbackPath;
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoMapper::RenderGPU(vtkRenderer* ren, vtkVolume* vol, vtkImageData* image,
  vtkDataArray* scalars, const std::vector<Surface>& surfaces, std::string& reason)
{
  Internals& impl = *this->Impl;
  auto* renWin = static_cast<vtkOpenGLRenderWindow*>(ren->GetRenderWindow());

  // 1. Capabilities, once per window.
  if (impl.Window != renWin)
  {
    if (impl.Window)
    {
      ScopedContext previous(impl.Window);
      impl.ReleaseGPU(impl.Window);
    }
    impl.Window = renWin;
  }
  if (!impl.Probed)
  {
    vtkNew<vtkMedicalGLCapabilities> caps;
    impl.Probed = true;
    impl.GPUUsable = caps->Probe(renWin);
    impl.GPUReason = caps->GetReason();
    impl.Max3DTextureSize = caps->GetMax3DTextureSize();
    renWin->MakeCurrent();
    GLint units = 0;
    glGetIntegerv(GL_MAX_VERTEX_TEXTURE_IMAGE_UNITS, &units);
    impl.MaxVertexTextureUnits = units;
    GLfloat pointSizes[2] = { 1.0f, 1.0f };
    glGetFloatv(GL_POINT_SIZE_RANGE, pointSizes);
    impl.MaxPointSize = pointSizes[1];
    GLfloat granularity = 0.0f;
    glGetFloatv(GL_POINT_SIZE_GRANULARITY, &granularity);
    impl.PointSizeGranularity = std::max(0.0f, std::min(granularity, 1.0f));
    // Early depth rejection with gl_FragDepth written (see the fragment shader).
    impl.ConservativeDepth = false;
    GLint numExtensions = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &numExtensions);
    for (GLint e = 0; e < numExtensions; ++e)
    {
      const char* name = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, e));
      if (name && std::string(name) == "GL_ARB_conservative_depth")
      {
        impl.ConservativeDepth = true;
      }
    }
    TakeGLErrors();
  }
  if (!impl.GPUUsable)
  {
    reason = impl.GPUReason;
    return false;
  }
  int dims[3];
  image->GetDimensions(dims);
  if (std::max({ dims[0], dims[1], dims[2] }) > impl.Max3DTextureSize)
  {
    std::ostringstream msg;
    msg << "the " << dims[0] << "x" << dims[1] << "x" << dims[2]
        << " volume exceeds GL_MAX_3D_TEXTURE_SIZE " << impl.Max3DTextureSize;
    reason = msg.str();
    return false;
  }

  renWin->MakeCurrent();
  vtkOpenGLState* ostate = renWin->GetState();

  // 2. The volume, uploaded again only when the array or its values change.
  const bool sameVolume = impl.UploadedArray == scalars &&
    impl.UploadedArrayTime == scalars->GetMTime() && impl.UploadedDims[0] == dims[0] &&
    impl.UploadedDims[1] == dims[1] && impl.UploadedDims[2] == dims[2];
  if (!sameVolume)
  {
    impl.PyramidValid = false;
    if (!impl.Pyramid->UploadVolume(renWin, scalars, dims))
    {
      impl.InvalidateGPU();
      reason = "the volume could not be uploaded as a 3D texture";
      return false;
    }
    ++this->NumberOfVolumeUploads;
    impl.UploadedArray = scalars;
    impl.UploadedArrayTime = scalars->GetMTime();
    std::copy(dims, dims + 3, impl.UploadedDims);
  }

  // 3. The pyramid, rebuilt only when the isovalues or the volume change.
  std::vector<double> isovalues;
  for (const Surface& s : surfaces)
  {
    isovalues.push_back(s.Value);
  }
  if (!impl.PyramidValid || isovalues != impl.BuiltIsovalues)
  {
    vtkNew<vtkTimerLog> timer;
    timer->StartTimer();
    if (!impl.Pyramid->Build(renWin, isovalues))
    {
      impl.InvalidateGPU();
      reason = "the HistoPyramid could not be built";
      return false;
    }
    timer->StopTimer(); // Build() ends by reading the total back: the passes are done
    this->LastBuildSeconds = timer->GetElapsedTime();
    this->LastBuildTilesDrawn = impl.Pyramid->GetLastTilesDrawn();
    this->LastBuildTiles = impl.Pyramid->GetNumberOfTiles();
    ++this->NumberOfPyramidBuilds;
    impl.BuiltIsovalues = isovalues;
    impl.PyramidValid = true;
  }
  const std::uint64_t total = impl.Pyramid->GetTotal();
  this->NumberOfPrimitives = total;
  if (total == 0)
  {
    return true; // nothing crosses: an empty, correct picture
  }
  if (total > static_cast<std::uint64_t>(INT_MAX))
  {
    reason = "more active cells than one draw call can take";
    return false;
  }

  // 4. The drawing program of this pyramid layout.
  const int numLevels = impl.Pyramid->GetNumberOfLevels();
  std::vector<std::array<int, 3>> sizes(numLevels);
  for (int l = 0; l < numLevels; ++l)
  {
    impl.Pyramid->GetLevelSize(l, sizes[l].data());
  }
  // Stored levels read by the vertex stage (1 .. numLevels - 2) and the volume.
  if (numLevels - 1 > impl.MaxVertexTextureUnits)
  {
    std::ostringstream msg;
    msg << "the pyramid needs " << numLevels - 1 << " vertex texture units, the context has "
        << impl.MaxVertexTextureUnits;
    reason = msg.str();
    return false;
  }
  std::ostringstream dec, descend, key;
  for (int l = 1; l + 1 < numLevels; ++l)
  {
    dec << "uniform usampler3D level" << l << ";\n";
  }
  // With one isovalue level 1 holds child masks: the last step down reads
  // the level-1 node's mask with the counts (see the vertex stage).
  const bool childMasks = impl.Pyramid->GetLevelOneHoldsChildMasks();
  for (int l = numLevels - 1; l >= 2; --l)
  {
    const int c = l - 1;
    const bool toMasks = childMasks && c == 1;
    descend << (toMasks ? "  descendToMasks(level" : "  descend(level") << c << ", ivec3("
            << sizes[c][0] / sizes[l][0] << ", " << sizes[c][1] / sizes[l][1] << ", "
            << sizes[c][2] / sizes[l][2] << "), vec3(" << sizes[0][0] / sizes[c][0] << ".0, "
            << sizes[0][1] / sizes[c][1] << ".0, " << sizes[0][2] / sizes[c][2]
            << ".0), node, index" << (toMasks ? ", nodeBits" : "") << ");\n";
  }
  const std::string declarations = impl.Pyramid->GetShaderDeclarations();

  // 5. Matrices: cell-index space (0-based on the extent) to view and clip.
  vtkNew<vtkMatrix4x4> indexToModel;
  {
    vtkNew<vtkMatrix4x4> shift;
    const int* extent = image->GetExtent();
    shift->SetElement(0, 3, extent[0]);
    shift->SetElement(1, 3, extent[2]);
    shift->SetElement(2, 3, extent[4]);
    vtkMatrix4x4::Multiply4x4(image->GetIndexToPhysicalMatrix(), shift, indexToModel);
  }
  vtkCamera* camera = ren->GetActiveCamera();
  const double aspect = ren->GetTiledAspectRatio();
  vtkNew<vtkMatrix4x4> indexToWorld, indexToView, indexToClip, viewToIndex;
  vtkMatrix4x4::Multiply4x4(vol->GetMatrix(), indexToModel, indexToWorld);
  vtkMatrix4x4::Multiply4x4(camera->GetModelViewTransformMatrix(), indexToWorld, indexToView);
  vtkMatrix4x4::Multiply4x4(
    camera->GetProjectionTransformMatrix(aspect, -1, 1), indexToView, indexToClip);
  vtkMatrix4x4::Invert(indexToView, viewToIndex);
  const bool parallel = camera->GetParallelProjection() != 0;
  double eye[4] = { 0.0, 0.0, parallel ? 1.0 : 0.0, parallel ? 0.0 : 1.0 };
  viewToIndex->MultiplyPoint(eye, eye);
  double gradientToView[9];
  {
    double linear[3][3], inverse[3][3];
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        linear[r][c] = indexToView->GetElement(r, c);
      }
    }
    vtkMath::Invert3x3(linear, inverse);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        gradientToView[3 * r + c] = inverse[c][r]; // transpose of the inverse
      }
    }
  }

  // 6. Isovalues in the pyramid's threshold order, their colours, lights.
  const std::vector<int> counted = impl.Pyramid->GetCountedIsovalues();
  float isoValues[8] = { 0 };
  float isoColors[32] = { 0 };
  bool translucent = false;
  for (std::size_t t = 0; t < counted.size() && t < 8; ++t)
  {
    const Surface& s = surfaces[counted[t]];
    isoValues[t] = static_cast<float>(s.Value);
    for (int c = 0; c < 3; ++c)
    {
      isoColors[4 * t + c] = static_cast<float>(s.Color[c]);
    }
    isoColors[4 * t + 3] = static_cast<float>(s.Opacity);
    translucent = translucent || s.Opacity < 1.0;
  }
  float lightDirections[3 * MaximumNumberOfLights] = { 0 };
  float lightColors[3 * MaximumNumberOfLights] = { 0 };
  int numLights = 0;
  {
    vtkLightCollection* lights = ren->GetLights();
    vtkCollectionSimpleIterator it;
    lights->InitTraversal(it);
    vtkMatrix4x4* worldToView = camera->GetModelViewTransformMatrix();
    while (vtkLight* light = lights->GetNextLight(it))
    {
      if (!light->GetSwitch() || numLights == MaximumNumberOfLights)
      {
        continue;
      }
      double position[3], focal[3], toLight[3];
      light->GetTransformedPosition(position);
      light->GetTransformedFocalPoint(focal);
      for (int a = 0; a < 3; ++a)
      {
        toLight[a] = position[a] - focal[a];
      }
      double view[3];
      for (int r = 0; r < 3; ++r)
      {
        view[r] = worldToView->GetElement(r, 0) * toLight[0] +
          worldToView->GetElement(r, 1) * toLight[1] + worldToView->GetElement(r, 2) * toLight[2];
      }
      if (vtkMath::Normalize(view) == 0.0)
      {
        continue;
      }
      const double* color = light->GetDiffuseColor();
      for (int a = 0; a < 3; ++a)
      {
        lightDirections[3 * numLights + a] = static_cast<float>(view[a]);
        lightColors[3 * numLights + a] = static_cast<float>(color[a] * light->GetIntensity());
      }
      ++numLights;
    }
  }

  // The footprint of this frame (see AllowPointFootprint) and the program of
  // this variant. The variants are compiled apart because a software
  // rasteriser runs every branch of a fragment shader under SIMD masks: an
  // opaque frame must not pay for the translucent code, nor for a loop over
  // lights with a uniform bound (which llvmpipe cannot unroll).
  GLint viewport[4] = { 0, 0, 1, 1 };
  glGetIntegerv(GL_VIEWPORT, viewport);
  const int cells[3] = { dims[0] - 1, dims[1] - 1, dims[2] - 1 };
  const int footprint = this->AllowPointFootprint &&
      PointsCoverCells(indexToView, camera->GetProjectionTransformMatrix(aspect, -1, 1), cells,
        camera->GetClippingRange()[0], parallel, viewport, impl.MaxPointSize)
    ? PointFootprint
    : BoxFootprint;
  // The first-hit pass (see SetFirstHitPass): opaque frames with point
  // footprints; its buffers are made here, before the program variant is
  // chosen, so that a context that cannot make them draws in one pass
  // instead.
  bool firstHit = this->FirstHitPass && footprint == PointFootprint && !translucent;
  if (firstHit)
  {
    ProjectedRectangle(indexToClip, cells, viewport, impl.HitRect);
  }
  if (firstHit && !this->PrepareFirstHit(renWin, impl.HitRect[2], impl.HitRect[3], viewport))
  {
    firstHit = false;
  }
  // Where the cells are drawn: the viewport's origin, or in the first-hit
  // pass that origin in buffers whose pixel (0, 0) is the window's pixel
  // (HitRect[0], HitRect[1]).
  const int drawViewport[2] = { firstHit ? viewport[0] - impl.HitRect[0] : viewport[0],
    firstHit ? viewport[1] - impl.HitRect[1] : viewport[1] };
  key << declarations.size() << declarations.substr(0, 80) << "|" << dec.str() << descend.str()
      << impl.ConservativeDepth;
  // Several opaque isovalues in the first-hit pass: one primitive per cell,
  // whose fragments take the nearest hit of the cell's isovalues (so that
  // the first hit in drawing order is the nearest; see the fragment stage).
  const bool nearest = firstHit && counted.size() > 1;
  // Translucent and `nearest` frames loop over the isovalues: their number
  // is part of the variant too.
  const int numIsovalues = static_cast<int>(std::min<std::size_t>(counted.size(), 8));
  std::ostringstream defines;
  if (footprint == PointFootprint)
  {
    defines << "#define MEDISO_POINT_FOOTPRINT\n";
  }
  if (translucent)
  {
    defines << "#define MEDISO_TRANSLUCENT\n";
  }
  if (firstHit)
  {
    defines << "#define MEDISO_FIRST_HIT\n";
  }
  if (nearest)
  {
    defines << "#define MEDISO_NEAREST\n";
  }
  if (childMasks)
  {
    defines << "#define MEDISO_CHILD_MASKS\n";
  }
  defines << "#define MEDISO_LIGHTS " << numLights << "\n";
  defines << "#define MEDISO_ISOVALUES " << (translucent || nearest ? numIsovalues : 8) << "\n";
  const std::string variant = defines.str();
  auto& cached = impl.Programs[variant];
  if (!cached.second || cached.first != key.str())
  {
    std::string vs = vtkHistoPyramidIso_vs;
    vtkShaderProgram::Substitute(vs, "//VTK::Variant::Dec", variant);
    vtkShaderProgram::Substitute(vs, "//VTK::HistoPyramidCommon::Dec", declarations);
    vtkShaderProgram::Substitute(vs, "//VTK::HistoPyramidLevels::Dec", dec.str());
    vtkShaderProgram::Substitute(vs, "//VTK::HistoPyramidLevels::Impl", descend.str());
    std::string fs = vtkHistoPyramidIso_fs;
    vtkShaderProgram::Substitute(fs, "//VTK::Variant::Dec", variant);
    vtkShaderProgram::Substitute(fs, "//VTK::ConservativeDepth::Dec",
      impl.ConservativeDepth && !firstHit
        ? "#extension GL_ARB_conservative_depth : require\nlayout(depth_greater) out float gl_FragDepth;\n"
        : "");
    cached.second = renWin->GetShaderCache()->ReadyShaderProgram(
      vs.c_str(), fs.c_str(), footprint == PointFootprint ? "" : vtkHistoPyramidIso_gs);
    if (!cached.second)
    {
      impl.Programs.erase(variant);
      reason = "the isosurface shaders do not build";
      impl.GPUUsable = false;
      impl.GPUReason = reason;
      return false;
    }
    cached.first = key.str();
  }
  else
  {
    renWin->GetShaderCache()->ReadyShaderProgram(cached.second);
  }
  vtkShaderProgram* program = cached.second;

  // 7. Draw, restoring every piece of state changed.
  vtkVolumeProperty* property = vol->GetProperty();
  TakeGLErrors();
  vtkOpenGLState::ScopedglEnableDisable blend(ostate, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthTest(ostate, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable cull(ostate, GL_CULL_FACE);
  vtkOpenGLState::ScopedglDepthMask depthMask(ostate);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFunc(ostate);
  vtkOpenGLState::ScopedglActiveTexture activeTexture(ostate);
  ostate->vtkglEnable(GL_DEPTH_TEST);
  ostate->vtkglDisable(GL_CULL_FACE);
  if (translucent)
  {
    ostate->vtkglEnable(GL_BLEND);
    ostate->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    ostate->vtkglDepthMask(GL_FALSE);
  }
  else
  {
    ostate->vtkglDisable(GL_BLEND);
    ostate->vtkglDepthMask(GL_TRUE);
  }

  std::vector<vtkTextureObject*> active;
  vtkTextureObject* volumeTexture = impl.Pyramid->GetVolumeTexture();
  volumeTexture->Activate();
  active.push_back(volumeTexture);
  impl.Pyramid->SetShaderUniforms(program);
  for (int l = 1; l + 1 < numLevels; ++l)
  {
    vtkTextureObject* level = impl.Pyramid->GetLevelTexture(l);
    level->Activate();
    active.push_back(level);
    const std::string name = "level" + std::to_string(l);
    program->SetUniformi(name.c_str(), level->GetTextureUnit());
  }
  const int firstFactor[3] = { sizes[0][0] / sizes[1][0], sizes[0][1] / sizes[1][1],
    sizes[0][2] / sizes[1][2] };
  SetUniformIVec3(program, "firstFactor", firstFactor);
  const float eyeIndex[4] = { static_cast<float>(eye[0]), static_cast<float>(eye[1]),
    static_cast<float>(eye[2]), static_cast<float>(eye[3]) };
  program->SetUniform4f("eyeIndex", eyeIndex);
  program->SetUniformi("backToFront", translucent ? 1 : 0);
  program->SetUniformi("oneRankPerCell", translucent || nearest ? 1 : 0);
  program->SetUniformi("parallelProjection", parallel ? 1 : 0);
  SetMatrix4(program, "indexToClip", indexToClip);
  SetMatrix4(program, "indexToView", indexToView);
  SetMatrix3(program, "gradientToView", gradientToView);
  program->SetUniform1fv("isovalues", 8, isoValues);
  program->SetUniform4fv("isoColors", 8, reinterpret_cast<const float(*)[4]>(isoColors));
  program->SetUniformf("ambient", static_cast<float>(property->GetAmbient()));
  program->SetUniformf("diffuse", static_cast<float>(property->GetDiffuse()));
  program->SetUniformf("specular", static_cast<float>(property->GetSpecular()));
  program->SetUniformf("specularPower", static_cast<float>(property->GetSpecularPower()));
  program->SetUniform3fv(
    "lightDirections", MaximumNumberOfLights, reinterpret_cast<const float(*)[3]>(lightDirections));
  program->SetUniform3fv(
    "lightColors", MaximumNumberOfLights, reinterpret_cast<const float(*)[3]>(lightColors));

  if (footprint == PointFootprint)
  {
    vtkNew<vtkMatrix4x4> clipToIndex;
    vtkMatrix4x4::Invert(indexToClip, clipToIndex);
    SetMatrix4(program, "clipToIndex", clipToIndex);
    const float viewportSize[2] = { static_cast<float>(viewport[2]),
      static_cast<float>(viewport[3]) };
    program->SetUniform2f("viewportSize", viewportSize);
    const float viewportF[4] = { static_cast<float>(drawViewport[0]),
      static_cast<float>(drawViewport[1]), static_cast<float>(viewport[2]),
      static_cast<float>(viewport[3]) };
    program->SetUniform4f("viewport", viewportF);
    program->SetUniformf("maxPointSize", impl.MaxPointSize);
    // Pixels whose centres lie on the square's edges stay covered whatever the
    // tie rule, and a size rounded down to the granularity still covers.
    program->SetUniformf("pointMargin", 0.1f + impl.PointSizeGranularity);
  }
  // The point size comes from the vertex stage (not tracked by vtkOpenGLState).
  const GLboolean programPointSize = glIsEnabled(GL_PROGRAM_POINT_SIZE);
  if (footprint == PointFootprint && !programPointSize)
  {
    glEnable(GL_PROGRAM_POINT_SIZE);
  }
  auto drawCells = [&]()
  {
    impl.VAO->Bind();
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(total));
    impl.VAO->Release();
  };
  if (firstHit)
  {
    // Pass 1: into the mapper's buffers, cleared to no hit; every point has
    // the same depth and the test is GL_LESS, so each pixel keeps its first
    // hit in drawing order (front to back: the nearest), and the test runs
    // before the fragment stage.
    ScopedFramebufferBindings savedBindings(impl.HitFBO);
    vtkOpenGLState::ScopedglViewport savedViewport(ostate);
    vtkOpenGLState::ScopedglEnableDisable scissor(ostate, GL_SCISSOR_TEST);
    vtkOpenGLState::ScopedglColorMask colorMask(ostate);
    vtkOpenGLState::ScopedglClearColor clearColor(ostate);
    vtkOpenGLState::ScopedglDepthFunc depthFunc(ostate);
    impl.HitFBO->Bind();
    impl.HitFBO->ActivateDrawBuffers(2);
    ostate->vtkglViewport(drawViewport[0], drawViewport[1], viewport[2], viewport[3]);
    ostate->vtkglDisable(GL_SCISSOR_TEST);
    ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    ostate->vtkglClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    ostate->vtkglClearDepth(1.0);
    ostate->vtkglClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    ostate->vtkglDepthFunc(GL_LESS);
    drawCells();
  }
  else
  {
    drawCells();
  }
  if (footprint == PointFootprint && !programPointSize)
  {
    glDisable(GL_PROGRAM_POINT_SIZE);
  }
  this->LastFootprint = footprint;
  this->LastFirstHitPass = firstHit;
  for (vtkTextureObject* texture : active)
  {
    texture->Deactivate();
  }
  if (firstHit && !this->CompositeFirstHit(renWin, reason))
  {
    impl.GPUUsable = false;
    impl.GPUReason = reason;
    return false;
  }
  const std::string errors = TakeGLErrors();
  if (!errors.empty())
  {
    reason = "drawing failed: " + errors;
    impl.GPUUsable = false;
    impl.GPUReason = reason;
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoMapper::PrepareFirstHit(
  vtkOpenGLRenderWindow* renWin, int rectWidth, int rectHeight, const int viewport[4])
{
  // Buffers for the volume's projection (HitRect), not the whole viewport:
  // rounded up to 64 pixels (at most the viewport's size), kept while the
  // projection fits in them, made again when it outgrows them or shrinks
  // to less than a quarter of their area (a zoom out).
  Internals& impl = *this->Impl;
  const int rounded[2] = { std::max(std::min((rectWidth + 63) / 64 * 64, viewport[2]), rectWidth),
    std::max(std::min((rectHeight + 63) / 64 * 64, viewport[3]), rectHeight) };
  if (impl.HitFBO && impl.HitSize[0] >= rectWidth && impl.HitSize[1] >= rectHeight &&
    static_cast<double>(impl.HitSize[0]) * impl.HitSize[1] <=
      4.0 * static_cast<double>(rounded[0]) * rounded[1])
  {
    return true;
  }
  const int width = rounded[0];
  const int height = rounded[1];
  impl.ReleaseHitBuffers(renWin);
  impl.HitColor = vtkSmartPointer<vtkTextureObject>::New();
  impl.HitDepth = vtkSmartPointer<vtkTextureObject>::New();
  impl.HitFlag = vtkSmartPointer<vtkTextureObject>::New();
  impl.HitFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
  impl.HitColor->SetContext(renWin);
  impl.HitDepth->SetContext(renWin);
  impl.HitFlag->SetContext(renWin);
  impl.HitFBO->SetContext(renWin);
  impl.HitDepth->SetInternalFormat(GL_R32F);
  impl.HitDepth->SetFormat(GL_RED);
  impl.HitDepth->SetDataType(GL_FLOAT);
  const auto w = static_cast<unsigned int>(width);
  const auto h = static_cast<unsigned int>(height);
  TakeGLErrors();
  const bool made = width > 0 && height > 0 &&
    impl.HitColor->Allocate2D(w, h, 4, VTK_UNSIGNED_CHAR) &&
    impl.HitDepth->Allocate2D(w, h, 1, VTK_FLOAT) &&
    impl.HitFlag->AllocateDepth(w, h, vtkTextureObject::Fixed16);
  std::string problem = made ? TakeGLErrors() : "the textures could not be allocated";
  if (problem.empty())
  {
    ScopedFramebufferBindings savedBindings(impl.HitFBO);
    impl.HitFBO->Bind();
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, impl.HitColor->GetHandle(), 0);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, impl.HitDepth->GetHandle(), 0);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, impl.HitFlag->GetHandle(), 0);
    const char* status = nullptr;
    if (!vtkOpenGLFramebufferObject::GetFrameBufferStatus(GL_FRAMEBUFFER, status))
    {
      problem = std::string("framebuffer incomplete (") + (status ? status : "?") + ")";
    }
    problem += TakeGLErrors();
  }
  if (!problem.empty())
  {
    impl.ReleaseHitBuffers(renWin);
    const std::string message =
      "first-hit pass unavailable (" + problem + "); drawing opaque surfaces in one pass";
    if (impl.Said.insert(message).second)
    {
      vtkWarningMacro(<< message);
    }
    return false;
  }
  impl.HitSize[0] = width;
  impl.HitSize[1] = height;
  return true;
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoMapper::CompositeFirstHit(vtkOpenGLRenderWindow* renWin, std::string& reason)
{
  // Pass 2: the first pass's colour and exact depth into the scene's
  // framebuffer over the pixels the buffers hold (HitRect, inside the
  // viewport), with the scene's depth test (enabled by the caller, with
  // depth writes, no blending).
  Internals& impl = *this->Impl;
  if (!impl.Composite)
  {
    impl.Composite.reset(new vtkOpenGLQuadHelper(renWin, nullptr, vtkHistoPyramidComposite_fs, ""));
  }
  else if (impl.Composite->Program)
  {
    renWin->GetShaderCache()->ReadyShaderProgram(impl.Composite->Program);
  }
  vtkShaderProgram* program = impl.Composite->Program;
  if (!program)
  {
    impl.Composite.reset();
    reason = "the first-hit composite shader does not build";
    return false;
  }
  impl.HitColor->Activate();
  impl.HitDepth->Activate();
  program->SetUniformi("hitColor", impl.HitColor->GetTextureUnit());
  program->SetUniformi("hitDepth", impl.HitDepth->GetTextureUnit());
  const float extent[2] = { static_cast<float>(impl.HitRect[2]), static_cast<float>(impl.HitRect[3]) };
  program->SetUniform2f("hitExtent", extent);
  {
    vtkOpenGLState* ostate = renWin->GetState();
    vtkOpenGLState::ScopedglViewport savedViewport(ostate);
    ostate->vtkglViewport(impl.HitRect[0], impl.HitRect[1], impl.HitRect[2], impl.HitRect[3]);
    impl.Composite->Render();
  }
  impl.HitColor->Deactivate();
  impl.HitDepth->Deactivate();
  const std::string errors = TakeGLErrors();
  if (!errors.empty())
  {
    reason = "compositing the first-hit pass failed: " + errors;
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::RenderFallback(vtkRenderer* ren, vtkVolume* vol,
  vtkImageData* image, vtkDataArray* scalars, const std::vector<Surface>& surfaces)
{
  Internals& impl = *this->Impl;

  // Contour an index-space copy of the image (origin 0, spacing 1, no
  // direction: vtkBlockLODContour needs an axis-aligned grid) and place it
  // with the actor's matrix, which also carries the volume's matrix.
  const int* extent = image->GetExtent();
  impl.IndexImage->SetExtent(0, extent[1] - extent[0], 0, extent[3] - extent[2], 0,
    extent[5] - extent[4]);
  impl.IndexImage->SetOrigin(0.0, 0.0, 0.0);
  impl.IndexImage->SetSpacing(1.0, 1.0, 1.0);
  if (impl.IndexImage->GetPointData()->GetScalars() != scalars)
  {
    impl.IndexImage->GetPointData()->Initialize();
    impl.IndexImage->GetPointData()->SetScalars(scalars);
    impl.IndexImage->Modified();
  }
  {
    vtkNew<vtkMatrix4x4> shift, indexToModel;
    shift->SetElement(0, 3, extent[0]);
    shift->SetElement(1, 3, extent[2]);
    shift->SetElement(2, 3, extent[4]);
    vtkMatrix4x4::Multiply4x4(image->GetIndexToPhysicalMatrix(), shift, indexToModel);
    vtkNew<vtkMatrix4x4> matrix;
    vtkMatrix4x4::Multiply4x4(vol->GetMatrix(), indexToModel, matrix);
    bool changed = false;
    for (int i = 0; i < 16; ++i)
    {
      changed = changed || impl.ActorMatrix->GetData()[i] != matrix->GetData()[i];
    }
    if (changed)
    {
      impl.ActorMatrix->DeepCopy(matrix);
    }
  }

  impl.Contour->SetInputData(impl.IndexImage);
  impl.Contour->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
  bool valuesChanged = impl.Contour->GetNumberOfContours() != static_cast<vtkIdType>(surfaces.size());
  for (std::size_t i = 0; i < surfaces.size() && !valuesChanged; ++i)
  {
    valuesChanged = impl.Contour->GetValue(static_cast<int>(i)) != surfaces[i].Value;
  }
  if (valuesChanged)
  {
    impl.Contour->SetNumberOfContours(static_cast<int>(surfaces.size()));
    for (std::size_t i = 0; i < surfaces.size(); ++i)
    {
      impl.Contour->SetValue(static_cast<int>(i), surfaces[i].Value);
    }
  }
  impl.Contour->Update();
  vtkPolyData* surface = impl.Contour->GetOutput();

  // Colour every point by its isovalue (RGBA, opacity in alpha).
  // Recoloured only when the surface or the looks change (not every frame).
  bool translucent = false;
  std::vector<double> looks;
  for (const Surface& s : surfaces)
  {
    translucent = translucent || s.Opacity < 1.0;
    looks.insert(looks.end(), { s.Value, s.Color[0], s.Color[1], s.Color[2], s.Opacity });
  }
  if (surface->GetMTime() != impl.ColoredSurfaceTime || looks != impl.ColoredLooks)
  {
    impl.Colored->ShallowCopy(surface);
    vtkDataArray* which = surface->GetPointData()->GetArray("Isovalue");
    vtkNew<vtkUnsignedCharArray> colors;
    colors->SetName("Colors");
    colors->SetNumberOfComponents(4);
    const vtkIdType numPoints = surface->GetNumberOfPoints();
    colors->SetNumberOfTuples(numPoints);
    for (vtkIdType p = 0; p < numPoints; ++p)
    {
      const double v = which ? which->GetTuple1(p) : surfaces[0].Value;
      const Surface* match = &surfaces[0];
      for (const Surface& s : surfaces)
      {
        if (std::abs(s.Value - v) < std::abs(match->Value - v))
        {
          match = &s;
        }
      }
      unsigned char rgba[4];
      for (int c = 0; c < 3; ++c)
      {
        rgba[c] = static_cast<unsigned char>(std::lround(255.0 * match->Color[c]));
      }
      rgba[3] = static_cast<unsigned char>(std::lround(255.0 * match->Opacity));
      colors->SetTypedTuple(p, rgba);
    }
    impl.Colored->GetPointData()->SetScalars(colors);
    impl.ColoredSurfaceTime = surface->GetMTime();
    impl.ColoredLooks = looks;
  }
  this->NumberOfFallbackTriangles = static_cast<std::uint64_t>(surface->GetNumberOfPolys());

  vtkVolumeProperty* property = vol->GetProperty();
  vtkProperty* actorProperty = impl.Actor->GetProperty();
  actorProperty->SetAmbient(property->GetAmbient());
  actorProperty->SetDiffuse(property->GetDiffuse());
  actorProperty->SetSpecular(property->GetSpecular());
  actorProperty->SetSpecularPower(property->GetSpecularPower());
  actorProperty->BackfaceCullingOff();

  auto* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!renWin)
  {
    return;
  }
  vtkOpenGLState* ostate = renWin->GetState();
  vtkOpenGLState::ScopedglEnableDisable blend(ostate, GL_BLEND);
  vtkOpenGLState::ScopedglDepthMask depthMask(ostate);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFunc(ostate);
  if (translucent)
  {
    impl.Sort->SetCamera(ren->GetActiveCamera());
    if (impl.PolyMapper->GetInputAlgorithm() != impl.Sort.GetPointer())
    {
      impl.PolyMapper->SetInputConnection(impl.Sort->GetOutputPort());
    }
    ostate->vtkglEnable(GL_BLEND);
    ostate->vtkglBlendFuncSeparate(
      GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    ostate->vtkglDepthMask(GL_FALSE);
  }
  else
  {
    if (impl.PolyMapper->GetInputAlgorithm() == impl.Sort.GetPointer())
    {
      impl.PolyMapper->SetInputData(impl.Colored);
    }
    ostate->vtkglDisable(GL_BLEND);
    ostate->vtkglDepthMask(GL_TRUE);
  }
  impl.PolyMapper->Render(ren, impl.Actor);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LastRenderPath: " << this->GetLastRenderPathAsString() << "\n";
  os << indent << "FallbackReason: " << this->FallbackReason << "\n";
  os << indent << "ForceCPUFallback: " << this->ForceCPUFallback << "\n";
  os << indent << "NumberOfPrimitives: " << this->NumberOfPrimitives << "\n";
  os << indent << "NumberOfPyramidBuilds: " << this->NumberOfPyramidBuilds << "\n";
  os << indent << "NumberOfVolumeUploads: " << this->NumberOfVolumeUploads << "\n";
  os << indent << "GPUMemoryBytes: " << this->GetGPUMemoryBytes() << "\n";
}
