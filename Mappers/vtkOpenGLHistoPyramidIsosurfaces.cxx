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
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWeakPointer.h"

#include "IsosurfaceScene.h"

#include <algorithm>
#include <chrono>
#include <functional>

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
// The core's scene, in the context of Window (the window of the last render).
struct vtkOpenGLHistoPyramidIsosurfaces::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  bool Probed = false;
  bool Usable = false;
  std::string Reason;
  mediso::IsosurfaceScene Scene{ ParallelFor };
  std::vector<Plane> ClipPlanes; // world coordinates
  int VolumeLevel = 3;           // mediso::IsosurfaceFrame::Level of the next frame
  double LastOneOffSeconds = 0.0; // GetLastOneOffSeconds()

  // Frees the scene's objects (the window's context must be current).
  void Release()
  {
    this->Scene.Release();
    this->Window = nullptr;
    this->Probed = false;
  }

  // The capability check and the scene's context, once per window.
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
        auto gl = vtkMedicalGLCapabilities::LoadCoreApi(window, this->Reason);
        this->Usable = gl != nullptr;
        this->Scene.SetContext(std::move(gl));
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
void vtkOpenGLHistoPyramidIsosurfaces::SetClipPlanes(const std::vector<Plane>& worldPlanes)
{
  this->Impl->ClipPlanes = worldPlanes;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramidIsosurfaces::SetVolumeLevel(int level)
{
  this->Impl->VolumeLevel = level;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramidIsosurfaces::SetGPUMemoryBudget(std::uint64_t bytes)
{
  this->Impl->Scene.SetGPUMemoryBudget(bytes);
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramidIsosurfaces::GetActivePairs(int level) const
{
  return this->Impl->Scene.GetActivePairs(level);
}

//------------------------------------------------------------------------------
std::vector<vtkOpenGLHistoPyramidIsosurfaces::Plane>
vtkOpenGLHistoPyramidIsosurfaces::PullBackPlanes(
  const std::vector<Plane>& planes, vtkMatrix4x4* toSpace)
{
  // A plane is a row vector: its value at M x is (plane M) x.
  std::vector<Plane> pulled;
  for (const Plane& plane : planes)
  {
    Plane p = { 0.0, 0.0, 0.0, 0.0 };
    for (int c = 0; c < 4; ++c)
    {
      for (int r = 0; r < 4; ++r)
      {
        p[c] += plane[r] * toSpace->GetElement(r, c);
      }
    }
    pulled.push_back(p);
  }
  return pulled;
}

//------------------------------------------------------------------------------
const mediso::IsosurfaceSceneStats& vtkOpenGLHistoPyramidIsosurfaces::GetStats() const
{
  return this->Impl->Scene.GetStats();
}

//------------------------------------------------------------------------------
std::string vtkOpenGLHistoPyramidIsosurfaces::GetBrickPoolReason() const
{
  return this->Impl->Scene.GetBrickPoolReason();
}

//------------------------------------------------------------------------------
double vtkOpenGLHistoPyramidIsosurfaces::GetLastOneOffSeconds() const
{
  return this->Impl->LastOneOffSeconds;
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramidIsosurfaces::GetGPUMemoryBytes() const
{
  return this->Impl->Scene.GetGPUMemoryBytes();
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramidIsosurfaces::GetFrameBufferBytes() const
{
  return this->Impl->Scene.GetFrameBufferBytes();
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramidIsosurfaces::RenderIsosurfaces(vtkRenderer* ren, vtkVolume* vol,
  vtkImageData* image, vtkDataArray* scalars, const std::vector<Surface>& surfaces,
  bool allowPointFootprint, bool firstHitPass, const SampleDistanceChooser& sampleDistance,
  std::string& reason)
{
  Internals& impl = *this->Impl;
  impl.LastOneOffSeconds = 0.0;
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

  // 1. The volume and the surfaces: the scene uploads when the array's
  //    values, type or size change (its modification time is the stamp) and
  //    builds when the isovalues change or after an upload.
  mediso::VolumeDescription volume;
  volume.Type = type;
  volume.Data = scalars->GetVoidPointer(0);
  image->GetDimensions(volume.Dims);
  volume.Stamp = scalars->GetMTime();
  const mediso::IsosurfaceSceneStats before = impl.Scene.GetStats();
  const auto oneOffStart = std::chrono::steady_clock::now();
  if (!impl.Scene.SetVolume(volume, reason))
  {
    return false;
  }
  std::vector<mediso::IsosurfaceLook> looks;
  for (const Surface& s : surfaces)
  {
    mediso::IsosurfaceLook look;
    look.Value = s.Value;
    for (int c = 0; c < 3; ++c)
    {
      look.Color[c] = static_cast<float>(s.Color[c]);
    }
    look.Opacity = static_cast<float>(s.Opacity);
    looks.push_back(look);
  }
  impl.Scene.SetSurfaces(looks);
  // Only the level drawn is built: an interactive frame on a coarse level right after a change
  // leaves the full volume's pyramid to the still frame.
  if (!impl.Scene.UpdateLevel(impl.VolumeLevel, reason))
  {
    return false;
  }
  const mediso::IsosurfaceSceneStats& after = impl.Scene.GetStats();
  if (after.VolumeUploads != before.VolumeUploads || after.PyramidBuilds != before.PyramidBuilds ||
    after.CoarseBuilds != before.CoarseBuilds)
  {
    impl.LastOneOffSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - oneOffStart).count();
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

  // 3. The material and the renderer's lights (view space, towards the
  //    light; diffuse colour times intensity).
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
  frame.ClipPlanes = PullBackPlanes(impl.ClipPlanes, indexToWorld);
  frame.Level = impl.VolumeLevel;
  if (sampleDistance)
  {
    frame.SampleDistance = sampleDistance(impl.Scene.GetActivePairs(impl.VolumeLevel));
  }

  // 4. Draw.
  if (!impl.Scene.Render(frame, reason))
  {
    // A program that does not build will not build next frame either.
    impl.Usable = false;
    impl.Reason = reason;
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramidIsosurfaces::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  const mediso::IsosurfaceSceneStats& stats = this->GetStats();
  os << indent << "NumberOfPrimitives: " << stats.Primitives << "\n";
  os << indent << "NumberOfPyramidBuilds: " << stats.PyramidBuilds << "\n";
  os << indent << "NumberOfVolumeUploads: " << stats.VolumeUploads << "\n";
  os << indent << "GPUMemoryBytes: " << this->GetGPUMemoryBytes() << "\n";
}
