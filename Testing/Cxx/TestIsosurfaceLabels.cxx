// SPDX-License-Identifier: BSD-3-Clause
// vtkIsosurfaceLabels on vtkBlockLODContour's surfaces of the phantom at skin
// and bone (the mesh the HistoPyramid Isosurface view makes):
// - the output holds the input's points and cells themselves (shallow copy);
// - each triangle's SurfaceIndex is the surface of its isovalue, its RGBA
//   SurfaceColor that surface's, given in any order of values;
// - field data: the names given (a made one where none is), the values, the
//   colours (white and opaque past those given), triangles per surface equal
//   to one-isovalue contours';
// - bad input (no point scalars, no SurfaceValues) gives one error and an
//   empty output; an empty input gives an empty output and no message.
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"
#include "vtkIsosurfaceLabels.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkTestErrorObserver.h"
#include "vtkUnsignedCharArray.h"

#include <string>

namespace
{
using medical_test::Check;

vtkIdType Triangles(vtkMedicalPhantomSource* phantom, double value)
{
  vtkNew<vtkBlockLODContour> contour;
  contour->SetInputConnection(phantom->GetOutputPort());
  contour->SetValue(0, value);
  contour->Update();
  return contour->GetOutput()->GetNumberOfCells();
}

// Runs the labels on `input`; checks that exactly one error mentioning
// `needle` came and the output is empty.
void ExpectError(vtkPolyData* input, int surfaces, const char* needle, const std::string& what)
{
  vtkNew<vtkIsosurfaceLabels> labels;
  vtkNew<vtkTest::ErrorObserver> observer;
  labels->AddObserver(vtkCommand::ErrorEvent, observer);
  labels->AddObserver(vtkCommand::WarningEvent, observer);
  labels->SetInputData(input);
  for (int s = 0; s < surfaces; ++s)
  {
    labels->SetSurfaceValue(s, 100.0 * s);
  }
  labels->Update();
  const std::string message = observer->GetErrorMessage();
  const std::size_t at = message.find(needle);
  Check(!observer->GetWarning() && at != std::string::npos &&
      message.find("ERROR", message.find("ERROR") + 1) == std::string::npos,
    what + ": one error mentioning '" + needle + "'");
  Check(
    labels->GetOutput()->GetNumberOfCells() == 0 && labels->GetOutput()->GetNumberOfPoints() == 0,
    what + ": an empty output");
}
}

int TestIsosurfaceLabels(int, char*[])
{
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(48, 48, 48);
  phantom->SetSpacing(4.0, 4.0, 4.0);
  vtkNew<vtkBlockLODContour> contour;
  contour->SetInputConnection(phantom->GetOutputPort());
  contour->SetNumberOfContours(2);
  contour->SetValue(0, -500.0);
  contour->SetValue(1, 400.0);
  contour->ComputeScalarsOn();

  vtkNew<vtkIsosurfaceLabels> labels;
  labels->SetInputConnection(contour->GetOutputPort());
  // Bone first: the order of the values, not of the contour, is the index.
  labels->SetSurfaceValue(0, 400.0);
  labels->SetSurfaceValue(1, -500.0);
  labels->SetSurfaceColor(0, 1.0, 0.0, 0.0, 1.0);
  labels->SetSurfaceName(0, "Bone");
  labels->Update();
  vtkPolyData* input = contour->GetOutput();
  vtkPolyData* output = labels->GetOutput();

  Check(output->GetNumberOfCells() == input->GetNumberOfCells() && input->GetNumberOfCells() > 0,
    "the same cells");
  Check(output->GetPoints() == input->GetPoints() &&
      output->GetPolys()->GetConnectivityArray() == input->GetPolys()->GetConnectivityArray(),
    "the input's points and cells themselves (a shallow copy)");

  auto* index = vtkIntArray::SafeDownCast(output->GetCellData()->GetArray("SurfaceIndex"));
  auto* color = vtkUnsignedCharArray::SafeDownCast(output->GetCellData()->GetArray("SurfaceColor"));
  vtkDataArray* isovalue = input->GetPointData()->GetScalars();
  const bool arrays = index && color && color->GetNumberOfComponents() == 4 && isovalue;
  Check(arrays, "SurfaceIndex (int) and SurfaceColor (RGBA) per cell");
  if (arrays)
  {
    vtkIdType wrong = 0;
    vtkIdType wrongColor = 0;
    const vtkIdType* ids = nullptr;
    vtkIdType size = 0;
    vtkCellArray* polys = output->GetPolys();
    for (vtkIdType c = 0; c < output->GetNumberOfCells(); ++c)
    {
      polys->GetCellAtId(c, size, ids);
      const int expected = isovalue->GetComponent(ids[0], 0) > 0.0 ? 0 : 1;
      wrong += index->GetValue(c) != expected;
      const unsigned char* rgba = color->GetPointer(4 * c);
      const bool red = rgba[0] == 255 && rgba[1] == 0 && rgba[2] == 0 && rgba[3] == 255;
      const bool white = rgba[0] == 255 && rgba[1] == 255 && rgba[2] == 255 && rgba[3] == 255;
      wrongColor += expected == 0 ? !red : !white;
    }
    Check(wrong == 0, "every triangle's SurfaceIndex is its isovalue's surface");
    Check(wrongColor == 0, "bone red as given, skin white and opaque (no colour given)");
  }
  vtkFieldData* field = output->GetFieldData();
  auto* names = vtkStringArray::SafeDownCast(field->GetAbstractArray("SurfaceNames"));
  Check(names && names->GetNumberOfValues() == 2 && names->GetValue(0) == "Bone" &&
      names->GetValue(1) == "Isovalue -500",
    "names: the one given, a made one for the other");
  vtkDataArray* triangles = field->GetArray("SurfaceTriangles");
  Check(triangles && triangles->GetComponent(0, 0) == Triangles(phantom, 400.0) &&
      triangles->GetComponent(1, 0) == Triangles(phantom, -500.0),
    "SurfaceTriangles: those of one-isovalue contours");
  Check(field->GetArray("SurfaceValues") && field->GetArray("SurfaceColors") &&
      field->GetArray("SurfaceColors")->GetNumberOfComponents() == 4,
    "SurfaceValues and RGBA SurfaceColors in the field data");

  // Bad input.
  vtkNew<vtkPolyData> noScalars;
  noScalars->ShallowCopy(input);
  noScalars->GetPointData()->SetScalars(nullptr);
  noScalars->GetPointData()->RemoveArray("Isovalue");
  ExpectError(noScalars, 2, "point scalars", "no point scalars");
  ExpectError(input, 0, "no SurfaceValues", "no SurfaceValues");
  vtkNew<vtkPolyData> empty;
  vtkNew<vtkIsosurfaceLabels> quiet;
  vtkNew<vtkTest::ErrorObserver> observer;
  quiet->AddObserver(vtkCommand::ErrorEvent, observer);
  quiet->AddObserver(vtkCommand::WarningEvent, observer);
  quiet->SetInputData(empty);
  quiet->Update();
  Check(
    !observer->GetError() && !observer->GetWarning() && quiet->GetOutput()->GetNumberOfCells() == 0,
    "an empty input: an empty output, no message");

  return medical_test::Finish("vtkIsosurfaceLabels: all checks passed");
}
