// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkPVMedicalHistogramInformation
 * @brief   The histogram of a source's point array, gathered from the data
 * server.
 *
 * The client knows a point array's range (vtkPVArrayInformation) but not how
 * its values are spread; the first isovalue chosen by Otsu's threshold
 * (vtkSMMedicalIsosurfaceInitializationHelper) needs the spread. This information object
 * counts, where the data lives, the values of one point array (by name, or the
 * active scalars when the name is empty) in the bins the client sets
 * (mediso::HistogramBins: SetBins), and sums the counts of every process.
 * Image data and other data sets are counted, composite data leaf by leaf;
 * anything else, or an array that is missing or has several components,
 * gives no bins (GetNumberOfBins() 0).
 *
 * Gathered with vtkSMSourceProxy::GatherInformation, like vtkPVDataInformation,
 * from the output port set with SetPortNumber.
 *
 * @sa vtkSMMedicalIsosurfaceInitializationHelper, HistogramThreshold.h
 */
#ifndef vtkPVMedicalHistogramInformation_h
#define vtkPVMedicalHistogramInformation_h

#include "MedicalIsosurfacesRepresentationsModule.h" // for export macro
#include "vtkPVInformation.h"

#include <string> // for the array name
#include <vector> // for the counts

class vtkDataObject;

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkPVMedicalHistogramInformation
  : public vtkPVInformation
{
public:
  static vtkPVMedicalHistogramInformation* New();
  vtkTypeMacro(vtkPVMedicalHistogramInformation, vtkPVInformation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The output port, the point array (empty: the active scalars) and the bins
  /// (the first at [low, low + width), `count` of them) to count in.
  vtkSetMacro(PortNumber, int);
  vtkGetMacro(PortNumber, int);
  void SetArrayName(const char* name) { this->ArrayName = name ? name : ""; }
  const char* GetArrayName() const { return this->ArrayName.c_str(); }
  void SetBins(double low, double width, int count);
  ///@}

  ///@{
  /// The counts after gathering (0 bins when nothing could be counted).
  int GetNumberOfBins() const { return static_cast<int>(this->Counts.size()); }
  double GetCount(int bin) const;
  ///@}

  void CopyFromObject(vtkObject* object) override;
  void AddInformation(vtkPVInformation* other) override;
  void CopyToStream(vtkClientServerStream* stream) override;
  void CopyFromStream(const vtkClientServerStream* stream) override;
  void CopyParametersToStream(vtkMultiProcessStream& stream) override;
  void CopyParametersFromStream(vtkMultiProcessStream& stream) override;

protected:
  vtkPVMedicalHistogramInformation();
  ~vtkPVMedicalHistogramInformation() override;

private:
  vtkPVMedicalHistogramInformation(const vtkPVMedicalHistogramInformation&) = delete;
  void operator=(const vtkPVMedicalHistogramInformation&) = delete;

  /// Adds a leaf's values; false when it has no such array.
  bool CountLeaf(vtkDataObject* leaf);

  int PortNumber = 0;
  std::string ArrayName;
  double Low = 0.0;
  double Width = 1.0;
  int BinCount = 0;
  std::vector<unsigned long long> Counts;
};

#endif
