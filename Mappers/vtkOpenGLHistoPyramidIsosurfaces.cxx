// SPDX-License-Identifier: BSD-3-Clause
#include "vtkOpenGLHistoPyramidIsosurfaces.h"

#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkMedicalCoreScalarType.h"
#include "vtkMedicalGLCapabilities.h"
#include "vtkMedicalGLUtilities.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkTimerLog.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWeakPointer.h"

#include "GLApi.h"
#include "HistoPyramidGL.h"
#include "IsosurfaceRendererGL.h"
#include "ProcessMemory.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <new>

vtkStandardNewMacro(vtkOpenGLHistoPyramidIsosurfaces);

namespace
{
using namespace medical_gl;


void ParallelFor(std::int64_t begin, std::int64_t end,
  const std::function<void(std::int64_t, std::int64_t)>& body)
{
  vtkSMPTools::For(static_cast<vtkIdType>(begin), static_cast<vtkIdType>(end),
    [&](vtkIdType b, vtkIdType e) { body(b, e); });
}
} // anonymous namespace

//------------------------------------------------------------------------------
// The core's objects, in the context of Window (the window of the last render).
struct vtkOpenGLHistoPyramidIsosurfaces::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  bool Probed = false;
  bool Usable = false;
  std::string Reason;
  std::shared_ptr<const mediso::GLApi> GL;
  std::unique_ptr<mediso::HistoPyramidGL> Pyramid;
  std::unique_ptr<mediso::IsosurfaceRendererGL> Renderer;

  // What the uploaded volume and the built pyramid were made from.
  vtkDataArray* UploadedArray = nullptr;
  vtkMTimeType UploadedArrayTime = 0;
  int UploadedDims[3] = { 0, 0, 0 };
  std::vector<double> BuiltIsovalues;

  // Frees the core's objects (the window's context must be current).
  void Release()
  {
    if (this->Pyramid)
    {
      this->Pyramid->Release();
    }
    if (this->Renderer)
    {
      this->Renderer->Release();
    }
    this->Pyramid.reset();
    this->Renderer.reset();
    this->GL.reset();
    this->UploadedArray = nullptr;
    this->UploadedArrayTime = 0;
    this->UploadedDims[0] = this->UploadedDims[1] = this->UploadedDims[2] = 0;
    this->BuiltIsovalues.clear();
    this->Window = nullptr;
    this->Probed = false;
  }

  // The capability check and the core's objects, once per window.
  bool Attach(vtkOpenGLRenderWindow* window, std::string& reason)
  {
    if (this->Window != window)
    {
      if (this->Window)
      {
        ScopedContext previous(this->Window);
        this->Release();
      }
      this->Window = window;
    }
    if (!this->Probed)
    {
      this->Probed = true;
      vtkNew<vtkMedicalGLCapabilities> caps;
      this->Usable = caps->Probe(window);
      this->Reason = caps->GetReason();
      if (this->Usable)
      {
        ScopedContext context(window);
        this->GL = vtkMedicalGLCapabilities::LoadCoreApi(window, this->Reason);
        this->Usable = this->GL != nullptr;
        if (this->Usable)
        {
          this->Pyramid.reset(new mediso::HistoPyramidGL(this->GL));
          this->Renderer.reset(new mediso::IsosurfaceRendererGL(this->GL));
        }
      }
    }
    reason = this->Reason;
    return this->Usable;
  }
};

//------------------------------------------------------------------------------
vtkOpenGLHistoPyramidIsosurfaces::vtkOpenGLHistoPyramidIsosurfaces()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkOpenGLHistoPyramidIsosurfaces::~vtkOpenGLHistoPyramidIsosurfaces()
{
  this->ReleaseGraphicsResources(nullptr);
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramidIsosurfaces::ReleaseGraphicsResources(vtkWindow* win)
{
  Internals& impl = *this->Impl;
  // The objects live in the context of the window they were made in; a call
  // for another window (a prop shown in several views) leaves them.
  if (impl.Window && (!win || win == impl.Window))
  {
    ScopedContext context(impl.Window);
    impl.Release();
  }
  else if (!impl.Window)
  {
    impl.Probed = false;
  }
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramidIsosurfaces::GetGPUMemoryBytes() const
{
  return this->Impl->Pyramid ? this->Impl->Pyramid->GetGPUMemoryBytes() : 0;
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramidIsosurfaces::GetFrameBufferBytes() const
{
  return this->Impl->Renderer ? this->Impl->Renderer->GetFrameBufferBytes() : 0;
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramidIsosurfaces::RenderIsosurfaces(vtkRenderer* ren, vtkVolume* vol,
  vtkImageData* image, vtkDataArray* scalars, const std::vector<Surface>& surfaces,
  bool allowPointFootprint, bool firstHitPass, std::string& reason)
{
  Internals& impl = *this->Impl;
  this->NumberOfPrimitives = 0;
  auto* renWin = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!renWin)
  {
    reason = "the render window is not an OpenGL window";
    return false;
  }
  if (!impl.Attach(renWin, reason))
  {
    return false;
  }
  mediso::ScalarType type;
  if (!vtkMedicalCoreScalarType(scalars->GetDataType(), type))
  {
    reason = std::string("the GPU path does not take ") + scalars->GetDataTypeAsString() + " data";
    return false;
  }
  ScopedContext context(renWin);

  // 1. The one rebuild decision: upload when the array, its values or the
  //    size change; build when the isovalues change or after an upload.
  int dims[3];
  image->GetDimensions(dims);
  const bool sameVolume = impl.UploadedArray == scalars &&
    impl.UploadedArrayTime == scalars->GetMTime() && std::equal(dims, dims + 3, impl.UploadedDims);
  std::vector<double> isovalues;
  for (const Surface& s : surfaces)
  {
    isovalues.push_back(s.Value);
  }
  if (!sameVolume)
  {
    impl.BuiltIsovalues.clear();
    impl.UploadedArray = nullptr;
    // UploadVolume's CPU-side copies: doubles converted to float, and rows
    // padded to a multiple of 4 points; past the allowance the CPU path
    // (with its own check) draws instead.
    const std::uint64_t points = static_cast<std::uint64_t>(dims[0]) * dims[1] * dims[2];
    const std::uint64_t valueBytes = type == mediso::ScalarType::Float64
      ? 4
      : static_cast<std::uint64_t>(scalars->GetDataTypeSize());
    std::uint64_t staging = type == mediso::ScalarType::Float64 ? 4 * points : 0;
    if (dims[0] % 4 != 0)
    {
      staging += static_cast<std::uint64_t>(dims[0] + 3) / 4 * 4 * valueBytes * dims[1] * dims[2];
    }
    if (staging > 0 &&
      !mediso::FitsInProcessMemory(staging, "the volume's copy for the GPU upload", reason))
    {
      return false;
    }
    bool uploaded = false;
    try
    {
      uploaded =
        impl.Pyramid->UploadVolume(type, scalars->GetVoidPointer(0), dims, ParallelFor, reason);
    }
    catch (const std::bad_alloc&)
    {
      reason = "memory ran out while copying the volume for the GPU upload";
    }
    if (!uploaded)
    {
      return false;
    }
    ++this->NumberOfVolumeUploads;
    impl.UploadedArray = scalars;
    impl.UploadedArrayTime = scalars->GetMTime();
    std::copy(dims, dims + 3, impl.UploadedDims);
  }
  if (isovalues != impl.BuiltIsovalues)
  {
    vtkNew<vtkTimerLog> timer;
    timer->StartTimer();
    impl.BuiltIsovalues.clear();
    if (!impl.Pyramid->Build(isovalues, reason))
    {
      return false;
    }
    timer->StopTimer(); // Build() ends by reading the total back: the passes are done
    this->LastBuildSeconds = timer->GetElapsedTime();
    this->LastBuildTilesDrawn = impl.Pyramid->GetLastTilesDrawn();
    this->LastBuildTiles = impl.Pyramid->GetNumberOfTiles();
    ++this->NumberOfPyramidBuilds;
    impl.BuiltIsovalues = isovalues;
  }

  // 2. The frame: cell-index space (0-based on the extent) to view and clip.
  mediso::IsosurfaceFrame frame;
  vtkNew<vtkMatrix4x4> indexToModel, indexToWorld, indexToView;
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
  vtkMatrix4x4::Multiply4x4(vol->GetMatrix(), indexToModel, indexToWorld);
  vtkMatrix4x4::Multiply4x4(camera->GetModelViewTransformMatrix(), indexToWorld, indexToView);
  std::copy(indexToView->GetData(), indexToView->GetData() + 16, frame.IndexToView);
  vtkMatrix4x4* projection = camera->GetProjectionTransformMatrix(aspect, -1, 1);
  std::copy(projection->GetData(), projection->GetData() + 16, frame.Projection);
  frame.Parallel = camera->GetParallelProjection() != 0;
  frame.NearPlane = camera->GetClippingRange()[0];
  int size[2], origin[2];
  ren->GetTiledSizeAndOrigin(&size[0], &size[1], &origin[0], &origin[1]);
  const int viewport[4] = { origin[0], origin[1], size[0], size[1] };
  std::copy(viewport, viewport + 4, frame.Viewport);

  // 3. The looks, the material and the renderer's lights (view space,
  //    towards the light; diffuse colour times intensity).
  for (const Surface& s : surfaces)
  {
    mediso::IsosurfaceLook look;
    look.Value = s.Value;
    for (int c = 0; c < 3; ++c)
    {
      look.Color[c] = static_cast<float>(s.Color[c]);
    }
    look.Opacity = static_cast<float>(s.Opacity);
    frame.Surfaces.push_back(look);
  }
  vtkVolumeProperty* property = vol->GetProperty();
  frame.Ambient = static_cast<float>(property->GetAmbient());
  frame.Diffuse = static_cast<float>(property->GetDiffuse());
  frame.Specular = static_cast<float>(property->GetSpecular());
  frame.SpecularPower = static_cast<float>(property->GetSpecularPower());
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  vtkMatrix4x4* worldToView = camera->GetModelViewTransformMatrix();
  while (vtkLight* light = lights->GetNextLight(it))
  {
    if (!light->GetSwitch() || frame.NumberOfLights == mediso::MaximumLights)
    {
      continue;
    }
    double position[3], focal[3], view[3];
    light->GetTransformedPosition(position);
    light->GetTransformedFocalPoint(focal);
    for (int r = 0; r < 3; ++r)
    {
      view[r] = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        view[r] += worldToView->GetElement(r, c) * (position[c] - focal[c]);
      }
    }
    if (vtkMath::Normalize(view) == 0.0)
    {
      continue;
    }
    const double* color = light->GetDiffuseColor();
    for (int a = 0; a < 3; ++a)
    {
      frame.LightDirections[frame.NumberOfLights][a] = static_cast<float>(view[a]);
      frame.LightColors[frame.NumberOfLights][a] = static_cast<float>(color[a] * light->GetIntensity());
    }
    ++frame.NumberOfLights;
  }
  frame.AllowPointFootprint = allowPointFootprint;
  frame.FirstHitPass = firstHitPass;

  // 4. Draw.
  mediso::IsosurfaceFrameStats stats;
  if (!impl.Renderer->Render(*impl.Pyramid, frame, stats, reason))
  {
    // A program that does not build will not build next frame either.
    impl.Usable = false;
    impl.Reason = reason;
    return false;
  }
  this->NumberOfPrimitives = stats.Primitives;
  this->LastPointFootprint = stats.PointFootprint;
  this->LastFirstHitPass = stats.FirstHit;
  return true;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramidIsosurfaces::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfPrimitives: " << this->NumberOfPrimitives << "\n";
  os << indent << "NumberOfPyramidBuilds: " << this->NumberOfPyramidBuilds << "\n";
  os << indent << "NumberOfVolumeUploads: " << this->NumberOfVolumeUploads << "\n";
  os << indent << "GPUMemoryBytes: " << this->GetGPUMemoryBytes() << "\n";
}
