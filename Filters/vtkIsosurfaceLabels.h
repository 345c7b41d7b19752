// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkIsosurfaceLabels
 * @brief   Marks each triangle of a multi-isovalue contour with its surface, colour and name.
 *
 * vtkIsosurfaceLabels takes the surfaces a contour filter made for several
 * isovalues at once (vtkBlockLODContour with ComputeScalars on: the point
 * scalars "Isovalue" hold each point's isovalue) and passes them through
 * unchanged (the same points and cells, shallow-copied), adding what a mesh
 * file needs to tell the surfaces apart:
 *
 * - cell data "SurfaceIndex" (int): the index of the triangle's surface in
 *   SurfaceValues, the surface whose value is nearest the isovalue of the
 *   triangle's first point (a contour's points all lie on one isovalue);
 * - cell data "SurfaceColor" (unsigned char, RGBA): that surface's colour and
 *   opacity, for writers and renderers that take colours from the data (PLY,
 *   VTP; ParaView draws it with Map Scalars off);
 * - field data "SurfaceNames" (strings), "SurfaceValues", "SurfaceColors"
 *   (RGBA as doubles, 0 to 1) and "SurfaceTriangles" (cells per surface):
 *   one tuple per surface, in the order given.
 *
 * The mesh made from a HistoPyramid Isosurface view (the panel's *Make
 * Mesh*, the Python call medical_isosurfaces.MakeMeshFromView()) is a Block
 * LOD Contour of the view's input followed by this filter, given the view's
 * isovalues, the colour and opacity each is drawn with, and a name each.
 *
 * Bad input (cells but no one-component point scalars, no SurfaceValues
 * while there are cells) gives one error and an empty output.
 *
 * @sa vtkBlockLODContour
 */
#ifndef vtkIsosurfaceLabels_h
#define vtkIsosurfaceLabels_h

#include "MedicalIsosurfacesFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <string> // For std::string
#include <vector> // For std::vector

class MEDICALISOSURFACESFILTERS_EXPORT vtkIsosurfaceLabels : public vtkPolyDataAlgorithm
{
public:
  static vtkIsosurfaceLabels* New();
  vtkTypeMacro(vtkIsosurfaceLabels, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The surfaces: an isovalue each (in the order the names and colours
   * follow), a colour and opacity (red, green, blue, alpha from 0 to 1;
   * white and opaque where none is given) and a name ("Isovalue <value>"
   * where none is given). No surfaces by default.
   */
  void SetNumberOfSurfaceValues(int number);
  void SetSurfaceValue(int i, double value);
  int GetNumberOfSurfaceValues() const { return static_cast<int>(this->Values.size()); }
  double GetSurfaceValue(int i) const;
  void SetNumberOfSurfaceColors(int number);
  void SetSurfaceColor(int i, double r, double g, double b, double a);
  void SetNumberOfSurfaceNames(int number);
  void SetSurfaceName(int i, const char* name);
  ///@}

protected:
  vtkIsosurfaceLabels() = default;
  ~vtkIsosurfaceLabels() override = default;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkIsosurfaceLabels(const vtkIsosurfaceLabels&) = delete;
  void operator=(const vtkIsosurfaceLabels&) = delete;

  std::vector<double> Values;
  std::vector<double> Colors; // r, g, b, a per surface
  std::vector<std::string> Names;
};

#endif
