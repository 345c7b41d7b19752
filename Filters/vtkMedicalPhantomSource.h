// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkMedicalPhantomSource
 * @brief   Deterministic synthetic CT head (int16, Hounsfield-like units).
 *
 * vtkMedicalPhantomSource produces a 3D image of an anatomical head phantom:
 * air (-1000 HU), scalp, face and neck soft tissue (40), skull and mandible (1100), a cervical
 * vertebra (800), CSF (5) around the brain (35), two ventricles, two eyes
 * carving the orbits, a soft-tissue lesion (70) and a small calcification
 * (600). Tissue boundaries are smooth, so the isosurfaces at the usual CT
 * isovalues (skin about -500 HU, bone about 400 HU) are smooth closed surfaces.
 *
 * It is the default input of the MedicalIsosurfaces plugin when no real data is
 * at hand, and the scaling input of its benchmarks: the same head is drawn at
 * any resolution (the phantom is defined on the normalised cube mapped onto the
 * whole extent), spacing and origin only place it in space.
 *
 * The algorithm lives in the VTK-free core class mediso::HeadPhantom
 * (Filters/Core/HeadPhantom.h), which documents the tissue model and the row-wise
 * evaluation. This class is the VTK shell: it validates parameters, honours
 * the requested update extent (so each MPI piece generates only its own part,
 * and pieces join exactly), runs the rows over vtkSMPTools, reports progress
 * and honours abort.
 *
 * Optional noise (NoiseStandardDeviation, HU) is seeded and a function of the
 * global voxel index only: output is identical whatever the SMP backend, thread
 * count or piece split.
 *
 * The output carries the point array "HU" (VTK_SHORT) and, in field data,
 * "ProducerProcessId": the id of the process that generated the data, so a
 * client can tell that a source ran on a server.
 *
 * @warning Values are HU-like, not calibrated to any scanner.
 * @warning Requests larger than the memory available on the machine are
 * refused with an error and an empty output, as are dimensions below 2.
 */
#ifndef vtkMedicalPhantomSource_h
#define vtkMedicalPhantomSource_h

#include "MedicalIsosurfacesFiltersModule.h" // For export macro
#include "vtkImageAlgorithm.h"

#include <string> // For std::string

class MEDICALISOSURFACESFILTERS_EXPORT vtkMedicalPhantomSource : public vtkImageAlgorithm
{
public:
  static vtkMedicalPhantomSource* New();
  vtkTypeMacro(vtkMedicalPhantomSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Number of points along x, y and z. Each must be at least 2. Default 128^3.
   */
  vtkSetVector3Macro(Dimensions, int);
  vtkGetVector3Macro(Dimensions, int);
  ///@}

  ///@{
  /**
   * Point spacing in world units (mm). Each must be positive. Default 1 1 1.
   */
  vtkSetVector3Macro(Spacing, double);
  vtkGetVector3Macro(Spacing, double);
  ///@}

  ///@{
  /**
   * World position of the first point. Default 0 0 0.
   */
  vtkSetVector3Macro(Origin, double);
  vtkGetVector3Macro(Origin, double);
  ///@}

  ///@{
  /**
   * Standard deviation (HU) of the additive noise; 0 (the default) means none.
   */
  vtkSetClampMacro(NoiseStandardDeviation, double, 0.0, 10000.0);
  vtkGetMacro(NoiseStandardDeviation, double);
  ///@}

  ///@{
  /**
   * Seed of the noise. The same seed always gives the same volume. Default 1.
   */
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /**
   * Upper bound, in MB (10^6 bytes), on the memory generation takes: the
   * output and a row of doubles per thread. 0 (the default) means what the
   * process may still allocate (mediso::ProcessMemoryAllowance(): the least
   * of the host's available physical memory, the address-space limit set by
   * `ulimit -v`, and the memory cgroup's limit); a positive bound applies
   * where it is below that. A request over the bound is refused with an
   * error and an empty output.
   */
  vtkSetClampMacro(MemoryLimit, double, 0.0, 1.0e12);
  vtkGetMacro(MemoryLimit, double);
  ///@}

protected:
  vtkMedicalPhantomSource();
  ~vtkMedicalPhantomSource() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Dimensions[3] = { 128, 128, 128 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double NoiseStandardDeviation = 0.0;
  int Seed = 1;
  double MemoryLimit = 0.0;

private:
  vtkMedicalPhantomSource(const vtkMedicalPhantomSource&) = delete;
  void operator=(const vtkMedicalPhantomSource&) = delete;

  // Empty string when the parameters are usable, else the reason.
  std::string CheckParameters();
  // The reason RequestInformation reported (empty when none), so that
  // RequestData reports a failure of its own (memory taken in between)
  // instead of staying silent, and does not repeat one.
  std::string ReportedProblem;
};

#endif
