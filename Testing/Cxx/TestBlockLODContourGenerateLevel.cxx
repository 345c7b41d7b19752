// SPDX-License-Identifier: BSD-3-Clause
// vtkBlockLODContour::GenerateLevel and EstimateLevelTriangles, what ParaView's
// interactive renders draw (vtkBlockLODSurfaceRepresentation):
// - before any update, for a level outside 0..3, after a change of the filter
//   not yet updated: false (or -1), an empty polydata, no message;
// - after an update, every level's surfaces equal those of a filter updated at
//   that level (triangles, points and normals value for value, the level in
//   "BlockLODLevel"), both isovalues together, and the filter's own output is
//   left as it was;
// - a level asked for again costs no extraction (the cache), and with the
//   cache off it is extracted again (still correct);
// - EstimateLevelTriangles is exact for the output's level and for a level
//   already made.
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <string>

namespace
{
using medical_test::Check;

bool SameValues(vtkDataArray* a, vtkDataArray* b)
{
  if (!a || !b || a->GetNumberOfValues() != b->GetNumberOfValues())
  {
    return false;
  }
  for (vtkIdType i = 0; i < a->GetNumberOfValues(); ++i)
  {
    if (a->GetVariantValue(i) != b->GetVariantValue(i))
    {
      return false;
    }
  }
  return true;
}

int LevelOf(vtkPolyData* surface)
{
  vtkDataArray* level = surface->GetFieldData()->GetArray("BlockLODLevel");
  return level ? static_cast<int>(level->GetTuple1(0)) : -2;
}

void Configure(vtkBlockLODContour* filter, vtkMedicalPhantomSource* phantom, int level)
{
  filter->SetInputConnection(phantom->GetOutputPort());
  filter->SetNumberOfContours(2);
  filter->SetValue(0, -500.0);
  filter->SetValue(1, 400.0);
  filter->SetLOD(level);
}
}

int TestBlockLODContourGenerateLevel(int, char*[])
{
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(72, 68, 64);

  vtkNew<vtkBlockLODContour> filter;
  Configure(filter, phantom, 3);
  vtkNew<vtkPolyData> made;
  Check(!filter->GenerateLevel(1, made) && made->GetNumberOfPoints() == 0,
    "no level before the first update");
  Check(filter->EstimateLevelTriangles(1) == -1.0, "no estimate before the first update");

  filter->Update();
  vtkPolyData* output = filter->GetOutput();
  const vtkIdType outputTriangles = output->GetNumberOfPolys();
  vtkDataArray* outputPoints = output->GetPoints()->GetData();
  Check(outputTriangles > 0 && LevelOf(output) == 3, "the output is level 3");
  Check(!filter->GenerateLevel(-1, made) && !filter->GenerateLevel(4, made) &&
      made->GetNumberOfPoints() == 0,
    "levels outside 0..3 are refused");
  Check(filter->EstimateLevelTriangles(3) == static_cast<double>(outputTriangles),
    "the output's level is estimated exactly");

  for (int level = 0; level < 4; ++level)
  {
    vtkNew<vtkBlockLODContour> reference;
    Configure(reference, phantom, level);
    reference->Update();
    vtkPolyData* expected = reference->GetOutput();
    const std::string at = "level " + std::to_string(level) + ": ";

    const vtkIdType extractions = filter->GetNumberOfExtractions();
    Check(filter->GenerateLevel(level, made), at + "made");
    Check(made->GetNumberOfPolys() == expected->GetNumberOfPolys() && made->GetNumberOfPolys() > 0,
      at + "as many triangles as a filter at that level (" +
        std::to_string(made->GetNumberOfPolys()) + " vs " +
        std::to_string(expected->GetNumberOfPolys()) + ")");
    Check(made->GetPoints() &&
        SameValues(made->GetPoints()->GetData(), expected->GetPoints()->GetData()),
      at + "the same points");
    Check(SameValues(made->GetPointData()->GetNormals(), expected->GetPointData()->GetNormals()),
      at + "the same normals");
    Check(LevelOf(made) == level, at + "BlockLODLevel says the level");
    Check(
      filter->EstimateLevelTriangles(level) == static_cast<double>(expected->GetNumberOfPolys()),
      at + "estimated exactly once made");
    // Level 3 is the output's own, cached by its update.
    Check((filter->GetNumberOfExtractions() - extractions) == (level == 3 ? 0 : 2),
      at + "extracts each isovalue once (or none for the output's level)");

    const vtkIdType before = filter->GetNumberOfExtractions();
    vtkNew<vtkPolyData> again;
    Check(
      filter->GenerateLevel(level, again) && again->GetNumberOfPolys() == made->GetNumberOfPolys(),
      at + "made again");
    Check(filter->GetNumberOfExtractions() == before, at + "the second time from the cache");
  }
  Check(output->GetNumberOfPolys() == outputTriangles && LevelOf(output) == 3 &&
      output->GetPoints()->GetData() == outputPoints,
    "the filter's own output is untouched");

  // A change not yet updated: the last output no longer describes the filter.
  filter->SetValue(1, 300.0);
  Check(!filter->GenerateLevel(1, made) && made->GetNumberOfPoints() == 0,
    "no level for a filter modified since its update");
  Check(filter->EstimateLevelTriangles(1) == -1.0, "no estimate for a modified filter");
  filter->Update();
  Check(
    filter->GenerateLevel(1, made) && made->GetNumberOfPolys() > 0, "a level again once updated");

  // Without a cache every request extracts, and is still right.
  vtkNew<vtkBlockLODContour> uncached;
  Configure(uncached, phantom, 3);
  uncached->SetCacheMemoryLimit(0);
  uncached->Update();
  vtkNew<vtkBlockLODContour> reference;
  Configure(reference, phantom, 2);
  reference->Update();
  vtkIdType extractions = uncached->GetNumberOfExtractions();
  Check(uncached->GenerateLevel(2, made) &&
      made->GetNumberOfPolys() == reference->GetOutput()->GetNumberOfPolys(),
    "without a cache: level 2 made");
  Check(uncached->GenerateLevel(2, made) && uncached->GetNumberOfExtractions() == extractions + 4,
    "without a cache: extracted each time");

  return medical_test::Finish("TestBlockLODContourGenerateLevel: every level matches, cache used");
}
