// SPDX-License-Identifier: BSD-3-Clause
#include "vtkBlockLODIsosurfaces.h"

#include "vtkActor.h"
#include "vtkBlockLODContour.h"
#include "vtkClipPolyData.h"
#include "vtkDataArray.h"
#include "vtkDepthSortPolyData.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkPlane.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtk_glew.h"

#include <array>
#include <cmath>

vtkStandardNewMacro(vtkBlockLODIsosurfaces);

//------------------------------------------------------------------------------
struct vtkBlockLODIsosurfaces::Internals
{
  vtkNew<vtkBlockLODContour> Contour;
  vtkNew<vtkImageData> IndexImage;
  vtkNew<vtkPolyData> Colored;
  vtkMTimeType ColoredSurfaceTime = 0; // Colored was made from this surface
  std::vector<double> ColoredLooks;    // and these values, colours, opacities
  // The coloured surface of each level drawn for the current input and looks,
  // so that switching levels (vtkHistoPyramidIsoMapper's interactive frames)
  // neither runs the filter nor recolours; ColoredLevel is the one in Colored.
  std::array<vtkSmartPointer<vtkPolyData>, 4> LevelColored;
  vtkMTimeType LevelInputTime = 0;
  std::vector<double> LevelLooks;
  int ColoredLevel = -1;
  // Translucent surfaces: the triangles sorted back to front for the current
  // camera (blending in drawing order is only right in that order).
  vtkNew<vtkDepthSortPolyData> Sort;
  vtkNew<vtkPolyDataMapper> PolyMapper;
  vtkNew<vtkActor> Actor;
  vtkNew<vtkMatrix4x4> ActorMatrix;
  // Clipping: the planes in world coordinates, the same in index space (the
  // space of Colored) and one clip filter per plane, chained after Colored.
  std::vector<Plane> WorldPlanes;
  std::vector<Plane> IndexPlanes;
  std::vector<vtkSmartPointer<vtkClipPolyData>> Clips;

  // The clip chain for `planes` (index space), remade only when they change.
  void SetIndexPlanes(const std::vector<Plane>& planes)
  {
    if (planes == this->IndexPlanes)
    {
      return;
    }
    this->IndexPlanes = planes;
    this->Clips.clear();
    for (const Plane& p : planes)
    {
      // vtkPlane's value n . (x - origin) is a x + b y + c z + d for the
      // origin -d n / |n|^2; vtkClipPolyData keeps its positive side.
      const double norm2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
      vtkNew<vtkPlane> plane;
      plane->SetNormal(p[0], p[1], p[2]);
      plane->SetOrigin(-p[3] * p[0] / norm2, -p[3] * p[1] / norm2, -p[3] * p[2] / norm2);
      auto clip = vtkSmartPointer<vtkClipPolyData>::New();
      clip->SetClipFunction(plane);
      if (this->Clips.empty())
      {
        clip->SetInputData(this->Colored);
      }
      else
      {
        clip->SetInputConnection(this->Clips.back()->GetOutputPort());
      }
      this->Clips.push_back(clip);
    }
    vtkAlgorithmOutput* shown = this->Clips.empty() ? nullptr : this->Clips.back()->GetOutputPort();
    if (shown)
    {
      this->Sort->SetInputConnection(shown);
    }
    else
    {
      this->Sort->SetInputData(this->Colored);
    }
    if (this->PolyMapper->GetInputAlgorithm() != this->Sort.GetPointer())
    {
      this->ConnectUnsorted();
    }
  }

  // The mapper's input without sorting: Colored, or its clipped copy.
  void ConnectUnsorted()
  {
    if (this->Clips.empty())
    {
      this->PolyMapper->SetInputData(this->Colored);
    }
    else
    {
      this->PolyMapper->SetInputConnection(this->Clips.back()->GetOutputPort());
    }
  }
};

//------------------------------------------------------------------------------
vtkBlockLODIsosurfaces::vtkBlockLODIsosurfaces()
  : Impl(new Internals)
{
  Internals& impl = *this->Impl;
  impl.Contour->SetLOD(3);
  // Set once: vtkAlgorithm::SetInputArrayToProcess marks the filter modified
  // on every call, which would extract (and recolour) again on every frame.
  impl.Contour->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
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
vtkBlockLODIsosurfaces::~vtkBlockLODIsosurfaces() = default;

//------------------------------------------------------------------------------
void vtkBlockLODIsosurfaces::SetClipPlanes(const std::vector<Plane>& worldPlanes)
{
  this->Impl->WorldPlanes = worldPlanes;
}

//------------------------------------------------------------------------------
void vtkBlockLODIsosurfaces::SetLevel(int level)
{
  this->Impl->Contour->SetLOD(level);
}

//------------------------------------------------------------------------------
int vtkBlockLODIsosurfaces::GetLevel() const
{
  return this->Impl->Contour->GetLOD();
}

//------------------------------------------------------------------------------
void vtkBlockLODIsosurfaces::ReleaseGraphicsResources(vtkWindow* win)
{
  this->Impl->PolyMapper->ReleaseGraphicsResources(win);
}

//------------------------------------------------------------------------------
void vtkBlockLODIsosurfaces::RenderIsosurfaces(vtkRenderer* ren, vtkVolume* vol,
  vtkImageData* image, vtkDataArray* scalars, const std::vector<Surface>& surfaces)
{
  Internals& impl = *this->Impl;

  // Contour an index-space copy of the image (origin 0, spacing 1, no
  // direction: the surface does not depend on where the image lies) and place
  // it with the actor's matrix, which also carries the volume's matrix.
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
  bool translucent = false;
  std::vector<double> looks;
  for (const Surface& s : surfaces)
  {
    translucent = translucent || s.Opacity < 1.0;
    looks.insert(looks.end(), { s.Value, s.Color[0], s.Color[1], s.Color[2], s.Opacity });
  }
  // A level already coloured for this input and these looks is drawn as it is.
  const int level = impl.Contour->GetLOD();
  const vtkMTimeType inputTime = impl.IndexImage->GetMTime();
  if (inputTime != impl.LevelInputTime || looks != impl.LevelLooks)
  {
    impl.LevelColored.fill(nullptr);
    impl.LevelInputTime = inputTime;
    impl.LevelLooks = looks;
  }
  vtkPolyData* cached = impl.LevelColored[static_cast<std::size_t>(level)];
  this->LastFrameExtracted = false;
  if (cached && impl.ColoredLevel != level)
  {
    impl.Colored->ShallowCopy(cached);
    impl.ColoredLevel = level;
  }
  vtkPolyData* surface = cached ? cached : impl.Contour->GetOutput();
  if (!cached)
  {
    const vtkMTimeType extractedBefore = impl.Contour->GetOutput()->GetMTime();
    impl.Contour->Update();
    this->LastFrameExtracted = surface->GetMTime() != extractedBefore;
  }

  // Colour every point by its isovalue (RGBA, opacity in alpha).
  // Recoloured only when the surface or the looks change (not every frame).
  if (!cached && (surface->GetMTime() != impl.ColoredSurfaceTime || looks != impl.ColoredLooks))
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
    auto copy = vtkSmartPointer<vtkPolyData>::New();
    copy->ShallowCopy(impl.Colored);
    impl.LevelColored[static_cast<std::size_t>(level)] = copy;
    impl.ColoredLevel = level;
  }
  impl.SetIndexPlanes(
    vtkOpenGLHistoPyramidIsosurfaces::PullBackPlanes(impl.WorldPlanes, impl.ActorMatrix));
  if (impl.Clips.empty())
  {
    this->NumberOfTriangles = static_cast<std::uint64_t>(surface->GetNumberOfPolys());
  }
  else
  {
    impl.Clips.back()->Update();
    this->NumberOfTriangles =
      static_cast<std::uint64_t>(impl.Clips.back()->GetOutput()->GetNumberOfPolys());
  }

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
      impl.ConnectUnsorted();
    }
    ostate->vtkglDisable(GL_BLEND);
    ostate->vtkglDepthMask(GL_TRUE);
  }
  impl.PolyMapper->Render(ren, impl.Actor);
}

//------------------------------------------------------------------------------
void vtkBlockLODIsosurfaces::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfTriangles: " << this->NumberOfTriangles << "\n";
}
