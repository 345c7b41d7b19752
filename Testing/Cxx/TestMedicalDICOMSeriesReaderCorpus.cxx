// SPDX-License-Identifier: BSD-3-Clause
// vtkMedicalDICOMSeriesReader on the generated DICOM corpus, in C++ so that
// the AddressSanitizer pass of Scripts/test.sh runs the reader and DCMTK's
// decoders over every file, the damaged ones included. Each case must read
// with the expected dimensions and type (the compressed series with the plain
// series' values) or be refused with the expected message and an empty image;
// the messages are caught by an observer and checked, never printed. The
// values themselves are checked case by case by TestMedicalDICOMSeriesReader.py.
//
//   TestMedicalDICOMSeriesReaderCorpus dicom_corpus.py OUT
//
// Exit 125 (skipped) when /usr/bin/python3 cannot write the corpus (no
// pydicom, or no DCMTK tools).
#include "vtkMedicalDICOMSeriesReader.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkTestErrorObserver.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <sys/wait.h>

namespace
{
struct Case
{
  const char* Path;    // under the corpus folder
  bool Resample;       // ResampleUnevenSlices
  int Dimensions[3];   // expected, when it reads
  int Type;            // expected scalar type, when it reads
  const char* Error;   // expected in the error, when refused
  const char* Warning; // expected in the warning, or nullptr for none
};

const Case Cases[] = {
  { "plain/slice_000.dcm", false, { 16, 12, 6 }, VTK_SHORT, nullptr, nullptr },
  { "rle/slice_003.dcm", false, { 16, 12, 6 }, VTK_SHORT, nullptr, nullptr },
  { "jpeg_lossless/slice_003.dcm", false, { 16, 12, 6 }, VTK_SHORT, nullptr, nullptr },
  { "jpegls/slice_003.dcm", false, { 16, 12, 6 }, VTK_SHORT, nullptr, nullptr },
  { "two_series/other_000.dcm", false, { 16, 12, 3 }, VTK_SHORT, nullptr,
    "the folder holds 2 series" },
  { "two_series", false, { 16, 12, 6 }, VTK_SHORT, nullptr, "the series with the most slices" },
  { "gap/slice_000.dcm", false, { 0, 0, 0 }, 0, "(1 slice missing)", nullptr },
  { "gap/slice_000.dcm", true, { 16, 12, 6 }, VTK_FLOAT, nullptr, "resampled 5 unevenly" },
  { "uneven/slice_000.dcm", false, { 0, 0, 0 }, 0, "a step of 3 mm between 4 mm", nullptr },
  { "uneven/slice_000.dcm", true, { 16, 12, 7 }, VTK_FLOAT, nullptr, "resampled 6 unevenly" },
  { "slopes/slice_000.dcm", false, { 16, 12, 6 }, VTK_FLOAT, nullptr, nullptr },
  { "junk/slice_000.dcm", false, { 16, 12, 6 }, VTK_SHORT, nullptr, nullptr },
  { "junk/notes.txt", false, { 0, 0, 0 }, 0, "not a DICOM image", nullptr },
  { "junk/random.bin", false, { 0, 0, 0 }, 0, "not a DICOM image", nullptr },
  { "junk/report.dcm", false, { 0, 0, 0 }, 0, "not a DICOM image", nullptr },
  { "jpeg2000/slice_000.dcm", false, { 0, 0, 0 }, 0,
    "transfer syntax \"JPEG 2000 (Lossless only)\"", nullptr },
  { "multiframe/enhanced.dcm", false, { 16, 12, 5 }, VTK_SHORT, nullptr, nullptr },
  { "shuffled/img_004.dcm", false, { 16, 12, 6 }, VTK_SHORT, nullptr, nullptr },
  { "oblique/o_2.dcm", false, { 16, 12, 4 }, VTK_SHORT, nullptr, nullptr },
  { "mr8/mr_2.dcm", false, { 16, 12, 3 }, VTK_UNSIGNED_CHAR, nullptr, nullptr },
  { "bigendian/be_2.dcm", false, { 16, 12, 3 }, VTK_SHORT, nullptr, nullptr },
  { "duplicate/slice_000.dcm", false, { 0, 0, 0 }, 0, "duplicate slices are not read", nullptr },
  { "mixed_size/slice_000.dcm", false, { 0, 0, 0 }, 0, "slices of different sizes", nullptr },
  { "tilted/slice_003.dcm", false, { 0, 0, 0 }, 0, "a gantry tilt or a sheared stack", nullptr },
  { "mixed_orientation/slice_000.dcm", false, { 0, 0, 0 }, 0, "slices of different orientations",
    nullptr },
  { "rgb/colour.dcm", false, { 0, 0, 0 }, 0, "only greyscale (MONOCHROME1/2)", nullptr },
  { "truncated/slice_000.dcm", false, { 0, 0, 0 }, 0, "(1 slice missing)",
    "slice_002.dcm (Invalid stream)" },
  { "truncated/slice_002.dcm", false, { 0, 0, 0 }, 0, "DCMTK cannot read it", nullptr },
  { "short_pixels/short.dcm", false, { 0, 0, 0 }, 0, "Pixel Data holds 100 bytes, 384 expected",
    nullptr },
  { "huge/huge.dcm", false, { 0, 0, 0 }, 0, "Pixel Data holds 64 bytes, 34358689800000 expected",
    nullptr },
  { "huge_rle/huge.dcm", false, { 0, 0, 0 }, 0,
    "a compressed file's decoding (68717379.6 MB) does not fit", nullptr },
  { "frames_claimed/frames.dcm", false, { 0, 0, 0 }, 0, "2000000000 frames without per-frame",
    nullptr },
  { "far_slice/slice_000.dcm", true, { 0, 0, 0 }, 0, "would take 100001 slices", nullptr },
  { "no_such_folder/x.dcm", false, { 0, 0, 0 }, 0, "no such file or folder", nullptr },
};

// Reads `path`; returns the scalars (or nullptr) and fills the messages.
vtkSmartPointer<vtkDataArray> Read(const std::string& path, bool resample, int dimensions[3],
  std::string& error, std::string& warning)
{
  vtkNew<vtkMedicalDICOMSeriesReader> reader;
  vtkNew<vtkTest::ErrorObserver> observer;
  reader->AddObserver(vtkCommand::ErrorEvent, observer);
  reader->AddObserver(vtkCommand::WarningEvent, observer);
  reader->SetFileName(path.c_str());
  reader->SetResampleUnevenSlices(resample);
  reader->Update();
  error = observer->GetError() ? observer->GetErrorMessage() : std::string();
  warning = observer->GetWarning() ? observer->GetWarningMessage() : std::string();
  vtkImageData* image = reader->GetOutput();
  image->GetDimensions(dimensions);
  vtkSmartPointer<vtkDataArray> scalars = image->GetPointData()->GetScalars();
  return scalars;
}

bool Same(vtkDataArray* a, vtkDataArray* b)
{
  if (!a || !b || a->GetDataType() != b->GetDataType() ||
    a->GetNumberOfValues() != b->GetNumberOfValues())
  {
    return false;
  }
  return std::memcmp(a->GetVoidPointer(0), b->GetVoidPointer(0),
           static_cast<std::size_t>(a->GetNumberOfValues()) * a->GetDataTypeSize()) == 0;
}
} // namespace

int main(int argc, char* argv[])
{
  if (argc != 3)
  {
    std::printf("usage: %s dicom_corpus.py OUT\n", argv[0]);
    return 2;
  }
  const std::string corpus = std::string(argv[2]) + "/dicom_corpus_cxx";
  const std::string command =
    std::string("/usr/bin/python3 '") + argv[1] + "' '" + corpus + "' > /dev/null";
  const int status = std::system(command.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 3 || code == 4 || code == 127)
  {
    std::printf("SKIP: /usr/bin/python3 cannot write the DICOM corpus (exit %d: pydicom or "
                "DCMTK's tools missing)\n",
      code);
    return 125;
  }
  if (code != 0)
  {
    std::printf("FAILED: the corpus writer exited with %d\n", code);
    return 1;
  }

  int failures = 0;
  vtkSmartPointer<vtkDataArray> plain;
  for (const Case& c : Cases)
  {
    int dimensions[3];
    std::string error, warning;
    vtkSmartPointer<vtkDataArray> scalars =
      Read(corpus + "/" + c.Path, c.Resample, dimensions, error, warning);
    bool ok = true;
    if (c.Error)
    {
      ok =
        error.find(c.Error) != std::string::npos && (!scalars || scalars->GetNumberOfTuples() == 0);
    }
    else
    {
      ok = error.empty() && scalars && scalars->GetDataType() == c.Type &&
        dimensions[0] == c.Dimensions[0] && dimensions[1] == c.Dimensions[1] &&
        dimensions[2] == c.Dimensions[2];
    }
    ok = ok && (c.Warning ? warning.find(c.Warning) != std::string::npos : warning.empty());
    if (ok && std::strncmp(c.Path, "plain/", 6) == 0)
    {
      plain = scalars;
    }
    const char* path = c.Path;
    if (ok &&
      (std::strncmp(path, "rle/", 4) == 0 || std::strncmp(path, "jpeg", 4) == 0 ||
        std::strncmp(path, "junk/slice", 10) == 0) &&
      !c.Error)
    {
      ok = Same(scalars, plain);
      if (!ok)
      {
        std::printf("FAILED: %s: values differ from the plain series'\n", path);
      }
    }
    if (!ok)
    {
      ++failures;
      std::printf("FAILED: %s%s: dimensions %d %d %d, type %s, error [%s], warning [%s]\n", path,
        c.Resample ? " (resampled)" : "", dimensions[0], dimensions[1], dimensions[2],
        scalars ? scalars->GetDataTypeAsString() : "none", error.c_str(), warning.c_str());
    }
    else
    {
      std::printf("ok: %s%s\n", path, c.Resample ? " (resampled)" : "");
    }
  }
  if (failures)
  {
    std::printf("%d case(s) failed\n", failures);
    return 1;
  }
  return 0;
}
