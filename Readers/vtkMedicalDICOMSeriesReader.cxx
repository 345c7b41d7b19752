// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMedicalDICOMSeriesReader.h"

#include "DICOMSeries.h"
#include "ProcessMemory.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkMedicalVTKType.h"

#include <vtksys/Directory.hxx>
#include <vtksys/SystemTools.hxx>

// DCMTK's configuration header comes before its other headers.
#include "dcmtk/config/osconfig.h"

#include "dcmtk/dcmdata/dcdeftag.h"
#include "dcmtk/dcmdata/dcdict.h"
#include "dcmtk/dcmdata/dcfilefo.h"
#include "dcmtk/dcmdata/dcitem.h"
#include "dcmtk/dcmdata/dcmetinf.h"
#include "dcmtk/dcmdata/dcrledrg.h"
#include "dcmtk/dcmdata/dcsequen.h"
#include "dcmtk/dcmdata/dcxfer.h"
#include "dcmtk/dcmjpeg/djdecode.h"
#include "dcmtk/dcmjpls/djdecode.h"
#include "dcmtk/oflog/oflog.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <mutex>
#include <new>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

vtkStandardNewMacro(vtkMedicalDICOMSeriesReader);

namespace
{
// DCMTK's decoders are process-wide registrations, made once whichever
// thread reads first. DCMTK's own log goes quiet below fatal: every failure
// it reports comes back as a condition that this reader turns into its one
// message.
void RegisterDecoders()
{
  static std::once_flag once;
  std::call_once(once,
    []
    {
      OFLog::configure(OFLogger::FATAL_LOG_LEVEL);
      DcmRLEDecoderRegistration::registerCodecs();
      DJDecoderRegistration::registerCodecs();
      DJLSDecoderRegistration::registerCodecs();
    });
}

// The transfer syntaxes read: the uncompressed ones DCMTK parses itself and
// the compressed ones the registered decoders handle.
bool Decodable(E_TransferSyntax syntax)
{
  switch (syntax)
  {
    case EXS_LittleEndianImplicit:
    case EXS_LittleEndianExplicit:
    case EXS_BigEndianExplicit:
    case EXS_DeflatedLittleEndianExplicit:
    case EXS_JPEGProcess1:
    case EXS_JPEGProcess2_4:
    case EXS_JPEGProcess6_8:
    case EXS_JPEGProcess10_12:
    case EXS_JPEGProcess14:
    case EXS_JPEGProcess14SV1:
    case EXS_JPEGLSLossless:
    case EXS_JPEGLSLossy:
    case EXS_RLELossless:
      return true;
    default:
      return false;
  }
}

std::string Number(double value)
{
  std::ostringstream text;
  text.precision(6);
  text << value;
  return text.str();
}

std::string BaseName(const std::string& path)
{
  return vtksys::SystemTools::GetFilenameName(path);
}

// One slice: a single-frame file, or one frame of a multi-frame file, as
// the shared slice rules see it (its Name is given when they run).
struct Slice : mediso::DICOMSlice
{
  unsigned long Frame = 0;
};

// What the scan keeps of one image file: what the shared per-file rules see
// (Name is the file's base name) and what DCMTK's decoding needs.
struct Instance : mediso::DICOMImageFormat
{
  std::string Path;
  std::string TransferSyntaxUID;
  E_TransferSyntax Syntax = EXS_Unknown;
  double SliceThickness = 0.0;
  bool PerFramePositions = true;
  // The Pixel Data's length in the file when uncompressed, else -1.
  long long NativePixelBytes = -1;
  std::vector<Slice> Slices;
};

std::string SliceName(const Instance& instance, const Slice& slice)
{
  std::string name = BaseName(instance.Path);
  if (instance.Frames > 1)
  {
    name += " frame " + std::to_string(slice.Frame + 1);
  }
  return name;
}

bool HasPart10Preamble(const std::string& path)
{
  std::ifstream file(path, std::ios::binary);
  char head[132];
  if (!file.read(head, sizeof(head)))
  {
    return false;
  }
  return head[128] == 'D' && head[129] == 'I' && head[130] == 'C' && head[131] == 'M';
}

bool ReadDoubles(DcmItem* item, const DcmTagKey& tag, double* values, int count)
{
  if (!item)
  {
    return false;
  }
  for (int i = 0; i < count; ++i)
  {
    Float64 value = 0.0;
    if (item->findAndGetFloat64(tag, value, static_cast<unsigned long>(i)).bad() ||
      !std::isfinite(value))
    {
      return false;
    }
    values[i] = value;
  }
  return true;
}

// An attribute of a frame: in the frame's functional group macro, else in
// the shared one, else at the top level of the dataset (a single-frame file).
bool FrameDoubles(DcmItem* perFrame, DcmItem* shared, DcmItem* top, const DcmTagKey& macro,
  const DcmTagKey& tag, double* values, int count)
{
  for (DcmItem* group : { perFrame, shared })
  {
    DcmItem* item = nullptr;
    if (group && group->findAndGetSequenceItem(macro, item, 0).good() &&
      ReadDoubles(item, tag, values, count))
    {
      return true;
    }
  }
  return ReadDoubles(top, tag, values, count);
}

enum class HeaderStatus
{
  Image,
  NotImage,
  Unreadable
};

// The attributes of one file, read up to (not into) its pixel data.
HeaderStatus ReadHeader(const std::string& path, Instance& instance, std::string& why)
{
  if (!HasPart10Preamble(path))
  {
    return HeaderStatus::NotImage;
  }
  DcmFileFormat file;
  // Values longer than 4 KB (the pixel data) stay on disk until asked for.
  const OFCondition status =
    file.loadFile(path.c_str(), EXS_Unknown, EGL_noChange, 4096, ERM_fileOnly);
  if (status.bad())
  {
    why = status.text();
    return HeaderStatus::Unreadable;
  }
  DcmDataset* data = file.getDataset();
  if (!data || !data->tagExists(DCM_PixelData) ||
    data->findAndGetUint16(DCM_Rows, instance.Rows).bad() ||
    data->findAndGetUint16(DCM_Columns, instance.Columns).bad())
  {
    return HeaderStatus::NotImage;
  }
  instance.Path = path;
  instance.Name = BaseName(path);
  OFString text;
  if (data->findAndGetOFString(DCM_SeriesInstanceUID, text).good())
  {
    instance.SeriesUID = text.c_str();
  }
  if (data->findAndGetOFString(DCM_SeriesDescription, text).good())
  {
    instance.SeriesDescription = text.c_str();
  }
  if (file.getMetaInfo() &&
    file.getMetaInfo()->findAndGetOFString(DCM_TransferSyntaxUID, text).good())
  {
    instance.TransferSyntaxUID = text.c_str();
    instance.Syntax = DcmXfer(text.c_str()).getXfer();
  }
  else
  {
    instance.Syntax = data->getOriginalXfer();
    instance.TransferSyntaxUID = DcmXfer(instance.Syntax).getXferID();
  }
  DcmElement* pixels = nullptr;
  if (!DcmXfer(instance.Syntax).isEncapsulated() &&
    data->findAndGetElement(DCM_PixelData, pixels).good() && pixels)
  {
    instance.NativePixelBytes = pixels->getLength();
  }
  data->findAndGetUint16(DCM_BitsAllocated, instance.BitsAllocated);
  if (data->findAndGetUint16(DCM_BitsStored, instance.BitsStored).bad())
  {
    instance.BitsStored = instance.BitsAllocated;
  }
  if (data->findAndGetUint16(DCM_HighBit, instance.HighBit).bad())
  {
    instance.HighBit = instance.BitsStored > 0 ? instance.BitsStored - 1 : 0;
  }
  data->findAndGetUint16(DCM_PixelRepresentation, instance.PixelRepresentation);
  if (data->findAndGetUint16(DCM_SamplesPerPixel, instance.SamplesPerPixel).bad())
  {
    instance.SamplesPerPixel = 1;
  }
  if (data->findAndGetOFString(DCM_PhotometricInterpretation, text).good())
  {
    instance.Photometric = text.c_str();
  }
  Sint32 frames = 1;
  if (data->findAndGetSint32(DCM_NumberOfFrames, frames).good() && frames > 1)
  {
    instance.Frames = static_cast<unsigned long>(frames);
  }
  long number = 0;
  Sint32 value = 0;
  if (data->findAndGetSint32(DCM_InstanceNumber, value).good())
  {
    number = value;
  }

  DcmItem* shared = nullptr;
  data->findAndGetSequenceItem(DCM_SharedFunctionalGroupsSequence, shared, 0);
  DcmSequenceOfItems* perFrame = nullptr;
  data->findAndGetSequence(DCM_PerFrameFunctionalGroupsSequence, perFrame);
  double thickness[1] = { 0.0 };
  if (FrameDoubles(
        nullptr, shared, data, DCM_PixelMeasuresSequence, DCM_SliceThickness, thickness, 1))
  {
    instance.SliceThickness = thickness[0];
  }
  instance.PerFramePositions =
    instance.Frames == 1 || (perFrame && perFrame->card() >= instance.Frames);
  if (!instance.PerFramePositions)
  {
    // Refused when its series is read; no slice is made for a frame count
    // that nothing in the file backs (a header may claim billions).
    return HeaderStatus::Image;
  }
  instance.Slices.resize(instance.Frames);
  DcmItem* group = nullptr;
  for (unsigned long f = 0; f < instance.Frames; ++f)
  {
    Slice& slice = instance.Slices[f];
    slice.Frame = f;
    slice.InstanceNumber = number;
    // Walked item after item: getItem(f) seeks from the first item each time.
    if (perFrame)
    {
      group = static_cast<DcmItem*>(perFrame->nextInContainer(group));
    }
    slice.HasPosition = FrameDoubles(
      group, shared, data, DCM_PlanePositionSequence, DCM_ImagePositionPatient, slice.Position, 3);
    slice.HasOrientation = FrameDoubles(group, shared, data, DCM_PlaneOrientationSequence,
      DCM_ImageOrientationPatient, slice.Orientation, 6);
    slice.HasPixelSpacing = FrameDoubles(
      group, shared, data, DCM_PixelMeasuresSequence, DCM_PixelSpacing, slice.PixelSpacing, 2);
    double rescale[1];
    if (FrameDoubles(
          group, shared, data, DCM_PixelValueTransformationSequence, DCM_RescaleSlope, rescale, 1))
    {
      slice.Slope = rescale[0];
    }
    if (FrameDoubles(group, shared, data, DCM_PixelValueTransformationSequence,
          DCM_RescaleIntercept, rescale, 1))
    {
      slice.Intercept = rescale[0];
    }
  }
  return HeaderStatus::Image;
}

// Linear interpolation along the normal from the sorted slices at
// `distances` onto `count` slices from distances[0] with `step`.
template <typename In, typename Out>
void ResampleSlices(const In* in, Out* out, std::size_t sliceSize,
  const std::vector<double>& distances, const std::vector<double>& slopes,
  const std::vector<double>& intercepts, int count, double step)
{
  std::size_t below = 0;
  for (int z = 0; z < count; ++z)
  {
    const double at = z + 1 == count ? distances.back() : distances.front() + z * step;
    while (below + 2 < distances.size() && distances[below + 1] <= at)
    {
      ++below;
    }
    const std::size_t above = std::min(below + 1, distances.size() - 1);
    double weight = 0.0;
    if (above != below)
    {
      weight = (at - distances[below]) / (distances[above] - distances[below]);
      weight = std::min(1.0, std::max(0.0, weight));
    }
    const In* a = in + below * sliceSize;
    const In* b = in + above * sliceSize;
    Out* to = out + static_cast<std::size_t>(z) * sliceSize;
    for (std::size_t p = 0; p < sliceSize; ++p)
    {
      const double va = slopes[below] * static_cast<double>(a[p]) + intercepts[below];
      const double vb = slopes[above] * static_cast<double>(b[p]) + intercepts[above];
      to[p] = static_cast<Out>(weight == 0.0 ? va : (1.0 - weight) * va + weight * vb);
    }
  }
}

// The stored values into `out`: rescaled slice by slice, or (resample)
// interpolated onto the even grid (float output).
template <typename In>
void Convert(const In* in, vtkDataArray* out, bool resample, std::size_t sliceSize,
  const std::vector<double>& distances, const std::vector<double>& slopes,
  const std::vector<double>& intercepts, int count, double step)
{
  if (resample)
  {
    ResampleSlices(in, static_cast<float*>(out->GetVoidPointer(0)), sliceSize, distances, slopes,
      intercepts, count, step);
    return;
  }
  switch (out->GetDataType())
  {
    vtkTemplateMacro(mediso::RescaleDICOMSlices(
      in, static_cast<VTK_TT*>(out->GetVoidPointer(0)), sliceSize, slopes, intercepts));
  }
}

// An array of `tuples` values of `type`, or nullptr with the message when
// its bytes (and `alongside` more, needed at the same time) do not fit or
// the allocation fails.
vtkSmartPointer<vtkDataArray> NewVolume(
  int type, std::size_t tuples, std::uint64_t alongside, const char* what, std::string& error)
{
  vtkSmartPointer<vtkDataArray> array;
  array.TakeReference(vtkDataArray::CreateDataArray(type));
  const std::uint64_t bytes =
    static_cast<std::uint64_t>(tuples) * static_cast<std::uint64_t>(array->GetDataTypeSize());
  if (!mediso::FitsInProcessMemory(bytes + alongside, what, error))
  {
    return nullptr;
  }
  if (!array->Allocate(static_cast<vtkIdType>(tuples)))
  {
    error = std::string("could not allocate ") + what + " (" + Number(bytes / 1.0e6) + " MB)";
    return nullptr;
  }
  array->SetNumberOfTuples(static_cast<vtkIdType>(tuples));
  return array;
}

std::string JoinList(const std::vector<std::string>& items, const char* separator)
{
  std::string text;
  for (const std::string& item : items)
  {
    text += (text.empty() ? "" : separator) + item;
  }
  return text;
}

// Step 1: the image files of the folder of `path` (or of the folder `path`).
struct FolderScan
{
  std::string Folder;
  bool FileOpened = false;
  std::string OpenedSeries;
  std::vector<Instance> Images;
  std::vector<std::string> Unreadable; // "name (reason)"
};

std::string ScanFolder(const std::string& path, FolderScan& scan)
{
  scan.FileOpened = !vtksys::SystemTools::FileIsDirectory(path);
  scan.Folder = scan.FileOpened ? vtksys::SystemTools::GetFilenamePath(path) : path;
  vtksys::Directory directory;
  if (!directory.Load(scan.Folder.empty() ? std::string(".") : scan.Folder))
  {
    return scan.Folder + ": the folder cannot be listed";
  }
  std::vector<std::string> names;
  for (unsigned long i = 0; i < directory.GetNumberOfFiles(); ++i)
  {
    const std::string name = directory.GetFile(i);
    if (name != "." && name != "..")
    {
      names.push_back(name);
    }
  }
  std::sort(names.begin(), names.end());
  bool openedFound = false;
  for (const std::string& name : names)
  {
    const std::string file = scan.Folder.empty() ? name : scan.Folder + "/" + name;
    // Folders, pipes and devices are skipped: opening a pipe would block.
    std::error_code failed;
    if (!std::filesystem::is_regular_file(file, failed))
    {
      continue;
    }
    Instance instance;
    std::string why;
    const HeaderStatus status = ReadHeader(file, instance, why);
    const bool isOpened = scan.FileOpened && vtksys::SystemTools::SameFile(file, path);
    if (status == HeaderStatus::Unreadable)
    {
      if (isOpened)
      {
        return path + ": DCMTK cannot read it (" + why + ")";
      }
      scan.Unreadable.push_back(name + " (" + why + ")");
      continue;
    }
    if (status == HeaderStatus::NotImage)
    {
      if (isOpened)
      {
        return path + ": not a DICOM image (no Part 10 preamble \"DICM\", or no Rows, Columns " +
          "and Pixel Data)";
      }
      continue;
    }
    if (isOpened)
    {
      openedFound = true;
      scan.OpenedSeries = instance.SeriesUID;
    }
    scan.Images.push_back(std::move(instance));
  }
  if (scan.FileOpened && !openedFound)
  {
    return path + ": not found in the listing of its folder";
  }
  if (scan.Images.empty())
  {
    return scan.Folder + ": no DICOM image files in the folder";
  }
  return std::string();
}

// Step 2: the images grouped by Series Instance UID, largest series first
// (so that every list of series reads the same way), and the one to read.
struct SeriesChoice
{
  std::vector<mediso::DICOMSeriesGroup> All;
  std::size_t Chosen = 0;
  std::string Reason;
};

std::string ChooseSeries(const FolderScan& scan, const std::string& wanted, SeriesChoice& choice)
{
  std::vector<const mediso::DICOMImageFormat*> images;
  for (const Instance& image : scan.Images)
  {
    images.push_back(&image);
  }
  choice.All = mediso::GroupDICOMSeries(images);
  const std::string* uid = nullptr;
  if (!wanted.empty())
  {
    uid = &wanted;
    choice.Reason = "the one SeriesInstanceUID names";
  }
  else if (scan.FileOpened)
  {
    uid = &scan.OpenedSeries;
    choice.Reason = "the series of the file opened";
  }
  else
  {
    choice.Chosen = 0;
    choice.Reason = "the series with the most slices";
    return std::string();
  }
  for (std::size_t s = 0; s < choice.All.size(); ++s)
  {
    if (choice.All[s].UID == *uid)
    {
      choice.Chosen = s;
      return std::string();
    }
  }
  std::vector<std::string> list;
  for (const mediso::DICOMSeriesGroup& s : choice.All)
  {
    list.push_back(mediso::DescribeDICOMSeries(s));
  }
  return scan.Folder + ": no series with Series Instance UID " + *uid + "; the folder holds " +
    JoinList(list, "; ");
}

// Step 4, file by file: what the reader decodes, and the same size and pixel
// format as the series' first file.
std::string CheckInstances(const std::vector<Instance*>& instances)
{
  const Instance& first = *instances.front();
  for (const Instance* instance : instances)
  {
    const std::string name = BaseName(instance->Path);
    if (!Decodable(instance->Syntax))
    {
      return name + ": transfer syntax \"" + DcmXfer(instance->Syntax).getXferName() + "\" (" +
        instance->TransferSyntaxUID + ") is not read (this reader decodes uncompressed, " +
        "deflated, JPEG baseline, extended and lossless, JPEG-LS and RLE pixel data)";
    }
    std::string error = mediso::CheckDICOMImageFormat(*instance);
    if (!error.empty())
    {
      return error;
    }
    if (!instance->PerFramePositions)
    {
      return name + ": " + std::to_string(instance->Frames) +
        " frames without per-frame positions (Per-frame Functional Groups, Plane Position " +
        "Sequence): their placement is unknown";
    }
    // Uncompressed pixel data shorter than the header says, known before
    // anything is allocated for it.
    if (instance->NativePixelBytes >= 0 &&
      static_cast<std::uint64_t>(instance->NativePixelBytes) < mediso::DICOMPixelBytes(*instance))
    {
      return mediso::DICOMShortPixelData(
        *instance, static_cast<std::uint64_t>(instance->NativePixelBytes));
    }
    error = mediso::CheckDICOMImageLikeFirst(*instance, first);
    if (!error.empty())
    {
      return error;
    }
  }
  return std::string();
}

// Steps 3 and 5: every slice of the series, checked against the first one,
// sorted along the normal and its steps measured against the median step, by
// the rules the web page's DICOM reading shares (mediso::StackDICOMSlices,
// Readers/Core/DICOMSeries.h).
struct Stack : mediso::DICOMStack
{
  std::vector<std::pair<const Instance*, const Slice*>> Slices; // in increasing position
};

std::string StackSlices(const std::vector<Instance*>& instances, Stack& stack)
{
  std::vector<std::pair<const Instance*, const Slice*>> slices;
  std::vector<mediso::DICOMSlice> rules;
  for (const Instance* instance : instances)
  {
    for (const Slice& slice : instance->Slices)
    {
      slices.emplace_back(instance, &slice);
      rules.push_back(slice);
      rules.back().Name = SliceName(*instance, slice);
    }
  }
  const std::string error = mediso::StackDICOMSlices(rules, stack);
  if (!error.empty())
  {
    return error;
  }
  for (std::size_t k : stack.Order)
  {
    stack.Slices.push_back(slices[k]);
  }
  return std::string();
}

// Stored values of DCMTK's pixel words (host order), by the shared rule.
template <typename Raw, typename Stored>
void Unpack(const Raw* raw, Stored* out, std::size_t count, const Instance& instance,
  std::int64_t& least, std::int64_t& greatest)
{
  mediso::UnpackDICOMValues(
    instance, count, [raw](std::size_t p) { return raw[p]; }, out, least, greatest);
}

// Step 6: every file decoded (DCMTK's codecs for the compressed ones) and
// its frames unpacked into `stored` at their place in the stack, with the
// least and greatest stored value of each slice.
std::string DecodeSlices(const std::vector<Instance*>& instances, const Stack& stack,
  vtkDataArray* stored, std::vector<std::int64_t>& least, std::vector<std::int64_t>& greatest)
{
  const Instance& first = *instances.front();
  const std::size_t sliceSize = static_cast<std::size_t>(first.Rows) * first.Columns;
  std::map<const Slice*, std::size_t> order;
  for (std::size_t k = 0; k < stack.Slices.size(); ++k)
  {
    order[stack.Slices[k].second] = k;
  }
  least.assign(stack.Slices.size(), 0);
  greatest.assign(stack.Slices.size(), 0);
  for (const Instance* instance : instances)
  {
    const std::string name = BaseName(instance->Path);
    DcmFileFormat file;
    OFCondition status = file.loadFile(
      instance->Path.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength, ERM_fileOnly);
    DcmDataset* data = file.getDataset();
    if (status.bad() || !data)
    {
      return name + ": DCMTK cannot read it (" + std::string(status.text()) + ")";
    }
    if (DcmXfer(instance->Syntax).isEncapsulated())
    {
      status = data->chooseRepresentation(EXS_LittleEndianExplicit, nullptr);
      if (status.bad() || !data->canWriteXfer(EXS_LittleEndianExplicit))
      {
        return name + ": DCMTK could not decode its \"" + DcmXfer(instance->Syntax).getXferName() +
          "\" pixel data (" + status.text() + ")";
      }
    }
    DcmElement* pixels = nullptr;
    if (data->findAndGetElement(DCM_PixelData, pixels).bad() || !pixels)
    {
      return name + ": no Pixel Data";
    }
    const void* raw = nullptr;
    if (first.BitsAllocated == 8)
    {
      Uint8* values = nullptr;
      status = pixels->getUint8Array(values);
      raw = values;
    }
    else
    {
      Uint16* values = nullptr;
      status = pixels->getUint16Array(values);
      raw = values;
    }
    if (status.bad() || !raw || pixels->getLength() < mediso::DICOMPixelBytes(*instance))
    {
      return mediso::DICOMShortPixelData(*instance, raw ? pixels->getLength() : 0);
    }
    for (const Slice& slice : instance->Slices)
    {
      const std::size_t k = order[&slice];
      std::int64_t lo = std::numeric_limits<std::int64_t>::max();
      std::int64_t hi = std::numeric_limits<std::int64_t>::min();
      const std::size_t at = slice.Frame * sliceSize;
      void* to = stored->GetVoidPointer(static_cast<vtkIdType>(k * sliceSize));
      switch (stored->GetDataType())
      {
        case VTK_UNSIGNED_CHAR:
          Unpack(static_cast<const Uint8*>(raw) + at, static_cast<unsigned char*>(to), sliceSize,
            *instance, lo, hi);
          break;
        case VTK_SIGNED_CHAR:
          Unpack(static_cast<const Uint8*>(raw) + at, static_cast<signed char*>(to), sliceSize,
            *instance, lo, hi);
          break;
        case VTK_UNSIGNED_SHORT:
          Unpack(static_cast<const Uint16*>(raw) + at, static_cast<unsigned short*>(to), sliceSize,
            *instance, lo, hi);
          break;
        default:
          Unpack(static_cast<const Uint16*>(raw) + at, static_cast<short*>(to), sliceSize,
            *instance, lo, hi);
          break;
      }
      least[k] = lo;
      greatest[k] = hi;
    }
  }
  return std::string();
}
} // namespace

//------------------------------------------------------------------------------
vtkMedicalDICOMSeriesReader::vtkMedicalDICOMSeriesReader()
{
  this->SetNumberOfInputPorts(0);
  this->SeriesList = vtkSmartPointer<vtkStringArray>::New();
}

//------------------------------------------------------------------------------
vtkMedicalDICOMSeriesReader::~vtkMedicalDICOMSeriesReader()
{
  this->SetFileName(nullptr);
  this->SetSeriesInstanceUID(nullptr);
}

//------------------------------------------------------------------------------
vtkStringArray* vtkMedicalDICOMSeriesReader::GetSeriesInFolder()
{
  return this->SeriesList;
}

//------------------------------------------------------------------------------
std::string vtkMedicalDICOMSeriesReader::ReadSeries()
{
  if (!this->FileName || !this->FileName[0])
  {
    return "no FileName: set a file of the series, or its folder";
  }
  const std::string path = this->FileName;
  if (!vtksys::SystemTools::FileExists(path))
  {
    return path + ": no such file or folder";
  }
  if (!dcmDataDict.isDictionaryLoaded())
  {
    return "DCMTK's data dictionary is not loaded (see DCMDICTPATH): no DICOM file can be read";
  }
  RegisterDecoders();

  // 1-2. Scan the folder, choose a series, say which others it holds.
  FolderScan scan;
  std::string error = ScanFolder(path, scan);
  if (!error.empty())
  {
    return error;
  }
  if (!scan.Unreadable.empty())
  {
    vtkWarningMacro(<< scan.Folder << ": skipped " << scan.Unreadable.size()
                    << " DICOM file(s) DCMTK cannot read: " << JoinList(scan.Unreadable, "; "));
  }
  SeriesChoice choice;
  error = ChooseSeries(scan, this->SeriesInstanceUID ? this->SeriesInstanceUID : "", choice);
  if (!error.empty())
  {
    return error;
  }
  const mediso::DICOMSeriesGroup& read = choice.All[choice.Chosen];
  std::vector<std::string> others;
  this->SeriesList->InsertNextValue(
    read.UID + " | " + read.Description + " | " + std::to_string(read.Slices) + " slices");
  for (std::size_t s = 0; s < choice.All.size(); ++s)
  {
    if (s != choice.Chosen)
    {
      const mediso::DICOMSeriesGroup& other = choice.All[s];
      others.push_back(mediso::DescribeDICOMSeries(other));
      this->SeriesList->InsertNextValue(
        other.UID + " | " + other.Description + " | " + std::to_string(other.Slices) + " slices");
    }
  }
  if (!others.empty())
  {
    vtkWarningMacro(<< scan.Folder << ": the folder holds " << choice.All.size() << " series; read "
                    << mediso::DescribeDICOMSeries(read) << ", " << choice.Reason << "; not read: "
                    << JoinList(others, "; ") << ". SeriesInstanceUID chooses another.");
  }

  // 3-5. Check the files and the slices; order them along the normal.
  std::vector<Instance*> instances;
  for (std::size_t i : read.Instances)
  {
    instances.push_back(&scan.Images[i]);
  }
  Stack stack;
  error = CheckInstances(instances);
  if (error.empty())
  {
    error = StackSlices(instances, stack);
  }
  if (!error.empty())
  {
    return error;
  }
  const Instance& first = *instances.front();
  if (!stack.ValidPixelSpacing)
  {
    vtkWarningMacro(<< BaseName(first.Path)
                    << ": no valid Pixel Spacing; 1 mm between rows and columns assumed");
  }
  const std::string unevenList = mediso::DICOMUnevenList(stack.Uneven);
  const bool resample = !stack.Uneven.empty();
  if (resample && !this->ResampleUnevenSlices)
  {
    return "the slices are not evenly spaced (median step " + Number(stack.Median) +
      " mm): " + unevenList + ". Turn ResampleUnevenSlices on to resample them onto an even grid.";
  }

  // 6. Decode every file into the stored values.
  const std::size_t count = stack.Slices.size();
  const std::size_t sliceSize = static_cast<std::size_t>(first.Rows) * first.Columns;
  const bool isSigned = first.PixelRepresentation == 1;
  const int storedType = first.BitsAllocated == 8 ? (isSigned ? VTK_SIGNED_CHAR : VTK_UNSIGNED_CHAR)
                                                  : (isSigned ? VTK_SHORT : VTK_UNSIGNED_SHORT);
  // DCMTK decodes a compressed file whole beside the stored volume.
  std::uint64_t decoding = 0;
  for (const Instance* instance : instances)
  {
    if (DcmXfer(instance->Syntax).isEncapsulated())
    {
      decoding = std::max(decoding, mediso::DICOMPixelBytes(*instance));
    }
  }
  vtkSmartPointer<vtkDataArray> stored = NewVolume(storedType, sliceSize * count, decoding,
    decoding ? "the decoded series and a compressed file's decoding" : "the decoded series", error);
  if (!stored)
  {
    return error;
  }
  std::vector<std::int64_t> least, greatest;
  error = DecodeSlices(instances, stack, stored, least, greatest);
  if (!error.empty())
  {
    return error;
  }

  // 7. Rescale (or resample) into the output type.
  std::vector<double> slopes(count), intercepts(count);
  for (std::size_t k = 0; k < count; ++k)
  {
    slopes[k] = stack.Slices[k].second->Slope;
    intercepts[k] = stack.Slices[k].second->Intercept;
  }
  // Resampled values are interpolated: float, whatever the rescaling.
  const int outputType = resample
    ? VTK_FLOAT
    : vtkMedicalVTKType(mediso::DICOMRescaledType(slopes, intercepts, least, greatest));
  const std::vector<double>& distances = stack.Distances;
  int slicesOut = static_cast<int>(count);
  double step = count > 1 ? (distances.back() - distances.front()) / (count - 1) : 0.0;
  if (resample)
  {
    const double span = distances.back() - distances.front();
    const double steps = std::round(span / stack.Median);
    if (!(steps < 65535.0))
    {
      return "the slices are not evenly spaced (median step " + Number(stack.Median) +
        " mm) and an even grid over their " + Number(span) + " mm would take " + Number(steps + 1) +
        " slices: not resampled";
    }
    slicesOut = static_cast<int>(steps) + 1;
    step = span / (slicesOut - 1);
  }
  vtkSmartPointer<vtkDataArray> volume = stored;
  if (resample || outputType != storedType || slopes[0] != 1.0 || intercepts[0] != 0.0)
  {
    volume = NewVolume(outputType, sliceSize * slicesOut, 0, "the rescaled series", error);
    if (!volume)
    {
      return error;
    }
    switch (storedType)
    {
      case VTK_UNSIGNED_CHAR:
        Convert(static_cast<const unsigned char*>(stored->GetVoidPointer(0)), volume, resample,
          sliceSize, distances, slopes, intercepts, slicesOut, step);
        break;
      case VTK_SIGNED_CHAR:
        Convert(static_cast<const signed char*>(stored->GetVoidPointer(0)), volume, resample,
          sliceSize, distances, slopes, intercepts, slicesOut, step);
        break;
      case VTK_UNSIGNED_SHORT:
        Convert(static_cast<const unsigned short*>(stored->GetVoidPointer(0)), volume, resample,
          sliceSize, distances, slopes, intercepts, slicesOut, step);
        break;
      default:
        Convert(static_cast<const short*>(stored->GetVoidPointer(0)), volume, resample, sliceSize,
          distances, slopes, intercepts, slicesOut, step);
        break;
    }
  }
  volume->SetName("DICOMImage");
  if (resample)
  {
    vtkWarningMacro(<< "resampled " << count << " unevenly spaced slices (median step "
                    << Number(stack.Median) << " mm: " << unevenList << ") onto " << slicesOut
                    << " slices " << Number(step)
                    << " mm apart by linear interpolation (ResampleUnevenSlices)");
  }

  // Placement.
  this->Volume = volume;
  this->SeriesRead = read.UID;
  this->Dimensions[0] = first.Columns;
  this->Dimensions[1] = first.Rows;
  this->Dimensions[2] = slicesOut;
  mediso::PlaceDICOMStack(stack, *stack.Slices.front().second, count, step, first.SliceThickness,
    this->Origin, this->Direction, this->Spacing);
  return std::string();
}

//------------------------------------------------------------------------------
int vtkMedicalDICOMSeriesReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  this->Volume = nullptr;
  this->SeriesRead.clear();
  this->SeriesList->Initialize();
  std::string error;
  try
  {
    error = this->ReadSeries();
  }
  catch (const std::bad_alloc&)
  {
    error = "out of memory while reading the series";
  }
  catch (const std::exception& e)
  {
    error = std::string("failed while reading the series: ") + e.what();
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (!error.empty())
  {
    this->Volume = nullptr;
    this->SeriesRead.clear();
    vtkErrorMacro(<< error);
    const int empty[6] = { 0, -1, 0, -1, 0, -1 };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), empty, 6);
    return 1;
  }
  const int whole[6] = { 0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0,
    this->Dimensions[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  outInfo->Set(vtkDataObject::SPACING(), this->Spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  outInfo->Set(vtkDataObject::DIRECTION(), this->Direction, 9);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, this->Volume->GetDataType(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkMedicalDICOMSeriesReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  if (!output)
  {
    return 0;
  }
  output->Initialize();
  if (!this->Volume)
  {
    return 1; // the error was reported with the information
  }
  output->SetExtent(
    0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0, this->Dimensions[2] - 1);
  output->SetSpacing(this->Spacing);
  output->SetOrigin(this->Origin);
  output->SetDirectionMatrix(this->Direction);
  output->GetPointData()->SetScalars(this->Volume);
  return 1;
}

//------------------------------------------------------------------------------
void vtkMedicalDICOMSeriesReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent
     << "SeriesInstanceUID: " << (this->SeriesInstanceUID ? this->SeriesInstanceUID : "(none)")
     << "\n";
  os << indent << "ResampleUnevenSlices: " << this->ResampleUnevenSlices << "\n";
  os << indent << "SeriesRead: " << this->SeriesRead << "\n";
  os << indent << "Origin: " << this->Origin[0] << " " << this->Origin[1] << " " << this->Origin[2]
     << "\n";
  os << indent << "Spacing: " << this->Spacing[0] << " " << this->Spacing[1] << " "
     << this->Spacing[2] << "\n";
}
