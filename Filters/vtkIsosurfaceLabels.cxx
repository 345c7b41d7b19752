// SPDX-License-Identifier: BSD-3-Clause
#include "vtkIsosurfaceLabels.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <sstream>

vtkStandardNewMacro(vtkIsosurfaceLabels);

//------------------------------------------------------------------------------
void vtkIsosurfaceLabels::SetNumberOfSurfaceValues(int number)
{
  const std::size_t size = static_cast<std::size_t>(std::max(0, number));
  if (size != this->Values.size())
  {
    this->Values.resize(size, 0.0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkIsosurfaceLabels::SetSurfaceValue(int i, double value)
{
  if (i < 0)
  {
    return;
  }
  if (static_cast<std::size_t>(i) >= this->Values.size())
  {
    this->SetNumberOfSurfaceValues(i + 1);
  }
  if (this->Values[static_cast<std::size_t>(i)] != value)
  {
    this->Values[static_cast<std::size_t>(i)] = value;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
double vtkIsosurfaceLabels::GetSurfaceValue(int i) const
{
  return i >= 0 && static_cast<std::size_t>(i) < this->Values.size()
    ? this->Values[static_cast<std::size_t>(i)]
    : 0.0;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceLabels::SetNumberOfSurfaceColors(int number)
{
  const std::size_t size = 4 * static_cast<std::size_t>(std::max(0, number));
  if (size != this->Colors.size())
  {
    this->Colors.resize(size, 1.0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkIsosurfaceLabels::SetSurfaceColor(int i, double r, double g, double b, double a)
{
  if (i < 0)
  {
    return;
  }
  if (4 * static_cast<std::size_t>(i) >= this->Colors.size())
  {
    this->SetNumberOfSurfaceColors(i + 1);
  }
  double* color = &this->Colors[4 * static_cast<std::size_t>(i)];
  if (color[0] != r || color[1] != g || color[2] != b || color[3] != a)
  {
    color[0] = r;
    color[1] = g;
    color[2] = b;
    color[3] = a;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkIsosurfaceLabels::SetNumberOfSurfaceNames(int number)
{
  const std::size_t size = static_cast<std::size_t>(std::max(0, number));
  if (size != this->Names.size())
  {
    this->Names.resize(size);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkIsosurfaceLabels::SetSurfaceName(int i, const char* name)
{
  if (i < 0)
  {
    return;
  }
  if (static_cast<std::size_t>(i) >= this->Names.size())
  {
    this->SetNumberOfSurfaceNames(i + 1);
  }
  const std::string given = name ? name : "";
  if (this->Names[static_cast<std::size_t>(i)] != given)
  {
    this->Names[static_cast<std::size_t>(i)] = given;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
int vtkIsosurfaceLabels::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* input = vtkPolyData::GetData(inputVector[0], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!input || !output)
  {
    return 0;
  }
  const vtkIdType cells = input->GetNumberOfCells();
  const std::size_t surfaces = this->Values.size();
  vtkDataArray* isovalues = input->GetPointData()->GetScalars();
  if (cells > 0 && (!isovalues || isovalues->GetNumberOfComponents() != 1))
  {
    vtkErrorMacro(<< "needs the isovalue of each point as one-component point scalars (Block LOD "
                     "Contour with Compute Scalars on); the output is empty.");
    return 1;
  }
  if (cells > 0 && surfaces == 0)
  {
    vtkErrorMacro(<< "no SurfaceValues: give the isovalues the surfaces were made for; the "
                     "output is empty.");
    return 1;
  }
  output->ShallowCopy(input);

  // The looks, with defaults for surfaces past the colours and names given.
  std::vector<double> colors(4 * surfaces, 1.0);
  std::copy_n(this->Colors.begin(), std::min(colors.size(), this->Colors.size()), colors.begin());
  vtkNew<vtkStringArray> names;
  names->SetName("SurfaceNames");
  names->SetNumberOfValues(static_cast<vtkIdType>(surfaces));
  vtkNew<vtkDoubleArray> values;
  values->SetName("SurfaceValues");
  values->SetNumberOfValues(static_cast<vtkIdType>(surfaces));
  vtkNew<vtkDoubleArray> surfaceColors;
  surfaceColors->SetName("SurfaceColors");
  surfaceColors->SetNumberOfComponents(4);
  surfaceColors->SetNumberOfTuples(static_cast<vtkIdType>(surfaces));
  std::vector<unsigned char> rgba(4 * surfaces);
  for (std::size_t s = 0; s < surfaces; ++s)
  {
    std::string name = s < this->Names.size() ? this->Names[s] : std::string();
    if (name.empty())
    {
      std::ostringstream made;
      made << "Isovalue " << this->Values[s];
      name = made.str();
    }
    names->SetValue(static_cast<vtkIdType>(s), name);
    values->SetValue(static_cast<vtkIdType>(s), this->Values[s]);
    for (std::size_t c = 0; c < 4; ++c)
    {
      const double channel = std::min(1.0, std::max(0.0, colors[4 * s + c]));
      surfaceColors->SetComponent(static_cast<vtkIdType>(s), static_cast<int>(c), channel);
      rgba[4 * s + c] = static_cast<unsigned char>(std::lround(255.0 * channel));
    }
  }

  // One label per cell, in vtkPolyData's cell order (verts, lines, polys, strips).
  vtkNew<vtkIntArray> index;
  index->SetName("SurfaceIndex");
  index->SetNumberOfTuples(cells);
  vtkNew<vtkUnsignedCharArray> color;
  color->SetName("SurfaceColor");
  color->SetNumberOfComponents(4);
  color->SetNumberOfTuples(cells);
  std::vector<vtkIdType> counts(surfaces, 0);
  vtkIdType cellId = 0;
  double lastValue = std::nan("");
  int lastSurface = 0;
  for (vtkCellArray* array :
    { input->GetVerts(), input->GetLines(), input->GetPolys(), input->GetStrips() })
  {
    if (!array)
    {
      continue;
    }
    auto it = vtk::TakeSmartPointer(array->NewIterator());
    for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell(), ++cellId)
    {
      vtkIdType size = 0;
      const vtkIdType* ids = nullptr;
      it->GetCurrentCell(size, ids);
      const double value = size > 0 ? isovalues->GetComponent(ids[0], 0) : lastValue;
      if (!(value == lastValue))
      {
        // Contours come surface by surface: the nearest value is looked up
        // only where the isovalue changes.
        lastValue = value;
        lastSurface = 0;
        for (std::size_t s = 1; s < surfaces; ++s)
        {
          if (std::abs(this->Values[s] - value) < std::abs(this->Values[lastSurface] - value))
          {
            lastSurface = static_cast<int>(s);
          }
        }
      }
      index->SetValue(cellId, lastSurface);
      color->SetTypedTuple(cellId, &rgba[4 * static_cast<std::size_t>(lastSurface)]);
      ++counts[static_cast<std::size_t>(lastSurface)];
    }
  }
  vtkNew<vtkIdTypeArray> triangles;
  triangles->SetName("SurfaceTriangles");
  triangles->SetNumberOfValues(static_cast<vtkIdType>(surfaces));
  for (std::size_t s = 0; s < surfaces; ++s)
  {
    triangles->SetValue(static_cast<vtkIdType>(s), counts[s]);
  }
  output->GetCellData()->AddArray(index);
  output->GetCellData()->AddArray(color);
  vtkFieldData* field = output->GetFieldData();
  field->AddArray(names);
  field->AddArray(values);
  field->AddArray(surfaceColors);
  field->AddArray(triangles);
  return 1;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceLabels::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Surfaces: " << this->Values.size() << "\n";
  for (std::size_t s = 0; s < this->Values.size(); ++s)
  {
    os << indent.GetNextIndent() << this->Values[s] << " "
       << (s < this->Names.size() ? this->Names[s] : std::string()) << "\n";
  }
}
