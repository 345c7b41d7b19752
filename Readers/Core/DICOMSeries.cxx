// SPDX-License-Identifier: BSD-3-Clause
#include "DICOMSeries.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <new>
#include <sstream>
#include <utility>

namespace mediso
{
namespace
{
const char* const ImplicitLittle = "1.2.840.10008.1.2";
const char* const ExplicitLittle = "1.2.840.10008.1.2.1";

// The reader's number format in messages (six significant digits).
std::string Number(double value)
{
  std::ostringstream text;
  text.precision(6);
  text << value;
  return text.str();
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

// ---------------------------------------------------------------------------
// The tag parser.

enum class HeaderStatus
{
  Image,
  NotImage,
  Unreadable
};

// A text value as DCMTK's findAndGetOFString gives it for the VRs read here:
// without the trailing padding (spaces, NULs); leading spaces kept except
// where the VR's own rule drops them (numbers are trimmed on parse).
std::string TrimmedText(const unsigned char* value, std::uint32_t length)
{
  std::string text(reinterpret_cast<const char*>(value), length);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\0'))
  {
    text.pop_back();
  }
  return text;
}

// The index-th of the backslash-separated numbers of a DS or IS value.
bool NumberAt(const std::string& text, int index, double& value)
{
  std::size_t begin = 0;
  for (int i = 0; i < index; ++i)
  {
    begin = text.find('\\', begin);
    if (begin == std::string::npos)
    {
      return false;
    }
    ++begin;
  }
  std::size_t end = text.find('\\', begin);
  std::string item = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
  const std::size_t first = item.find_first_not_of(' ');
  const std::size_t last = item.find_last_not_of(' ');
  if (first == std::string::npos)
  {
    return false;
  }
  item = item.substr(first, last - first + 1);
  // Decimal notation only (DS, IS): strtod's "inf", "nan" and hexadecimal forms are not DICOM's.
  if (item.find_first_not_of("0123456789+-.eE") != std::string::npos)
  {
    return false;
  }
  char* stop = nullptr;
  value = std::strtod(item.c_str(), &stop);
  return stop && *stop == '\0' && std::isfinite(value);
}

bool Doubles(const std::string& text, bool present, double* values, int count)
{
  if (!present)
  {
    return false;
  }
  double read[6];
  for (int i = 0; i < count; ++i)
  {
    if (!NumberAt(text, i, read[i]))
    {
      return false;
    }
  }
  std::copy(read, read + count, values);
  return true;
}

// What one file's header holds (the top-level elements the rules use).
struct Header
{
  std::string TransferSyntaxUID;
  std::map<std::uint32_t, std::string> Text;    // DS, IS, UI, CS, LO values
  std::map<std::uint32_t, std::uint16_t> Short; // US values
  bool FunctionalGroups = false;
  bool HasPixelData = false;
  bool Encapsulated = false;
  std::uint64_t PixelOffset = 0;
  std::uint64_t PixelLength = 0;
};

constexpr std::uint32_t Tag(std::uint16_t group, std::uint16_t element)
{
  return (static_cast<std::uint32_t>(group) << 16) | element;
}

constexpr std::uint32_t TransferSyntaxTag = Tag(0x0002, 0x0010);
constexpr std::uint32_t SeriesDescriptionTag = Tag(0x0008, 0x103E);
constexpr std::uint32_t SliceThicknessTag = Tag(0x0018, 0x0050);
constexpr std::uint32_t SeriesUIDTag = Tag(0x0020, 0x000E);
constexpr std::uint32_t InstanceNumberTag = Tag(0x0020, 0x0013);
constexpr std::uint32_t PositionTag = Tag(0x0020, 0x0032);
constexpr std::uint32_t OrientationTag = Tag(0x0020, 0x0037);
constexpr std::uint32_t SamplesTag = Tag(0x0028, 0x0002);
constexpr std::uint32_t PhotometricTag = Tag(0x0028, 0x0004);
constexpr std::uint32_t FramesTag = Tag(0x0028, 0x0008);
constexpr std::uint32_t RowsTag = Tag(0x0028, 0x0010);
constexpr std::uint32_t ColumnsTag = Tag(0x0028, 0x0011);
constexpr std::uint32_t PixelSpacingTag = Tag(0x0028, 0x0030);
constexpr std::uint32_t BitsAllocatedTag = Tag(0x0028, 0x0100);
constexpr std::uint32_t BitsStoredTag = Tag(0x0028, 0x0101);
constexpr std::uint32_t HighBitTag = Tag(0x0028, 0x0102);
constexpr std::uint32_t RepresentationTag = Tag(0x0028, 0x0103);
constexpr std::uint32_t InterceptTag = Tag(0x0028, 0x1052);
constexpr std::uint32_t SlopeTag = Tag(0x0028, 0x1053);
constexpr std::uint32_t SharedGroupsTag = Tag(0x5200, 0x9229);
constexpr std::uint32_t PerFrameGroupsTag = Tag(0x5200, 0x9230);
constexpr std::uint32_t PixelDataTag = Tag(0x7FE0, 0x0010);
constexpr std::uint32_t ItemTag = Tag(0xFFFE, 0xE000);
constexpr std::uint32_t ItemEndTag = Tag(0xFFFE, 0xE00D);
constexpr std::uint32_t SequenceEndTag = Tag(0xFFFE, 0xE0DD);
constexpr std::uint32_t Undefined = 0xFFFFFFFFu;

// The dictionary VR of an attribute the rules use, or nullptr for the others.
const char* RuleVR(std::uint32_t tag)
{
  switch (tag)
  {
    case TransferSyntaxTag:
    case SeriesUIDTag:
      return "UI";
    case SeriesDescriptionTag:
      return "LO";
    case SliceThicknessTag:
    case PositionTag:
    case OrientationTag:
    case PixelSpacingTag:
    case InterceptTag:
    case SlopeTag:
      return "DS";
    case InstanceNumberTag:
    case FramesTag:
      return "IS";
    case PhotometricTag:
      return "CS";
    case SamplesTag:
    case RowsTag:
    case ColumnsTag:
    case BitsAllocatedTag:
    case BitsStoredTag:
    case HighBitTag:
    case RepresentationTag:
      return "US";
    default:
      return nullptr;
  }
}

class Parser
{
public:
  Parser(const unsigned char* bytes, std::size_t size)
    : Bytes(bytes)
    , Size(size)
  {
  }

  const unsigned char* Bytes;
  std::size_t Size;
  std::size_t At = 0;
  std::string Why;

  bool Fail(const std::string& why)
  {
    if (this->Why.empty())
    {
      this->Why = why;
    }
    return false;
  }
  bool Has(std::uint64_t count) const
  {
    return this->At <= this->Size && this->Size - this->At >= count;
  }
  std::uint16_t U16(std::size_t at) const
  {
    return static_cast<std::uint16_t>(this->Bytes[at] | (this->Bytes[at + 1] << 8));
  }
  std::uint32_t U32(std::size_t at) const
  {
    return static_cast<std::uint32_t>(this->U16(at)) |
      (static_cast<std::uint32_t>(this->U16(at + 2)) << 16);
  }

  // One element's header at At: its tag, VR (explicit only) and length.
  bool ElementHeader(bool explicitVR, std::uint32_t& tag, char vr[2], std::uint32_t& length)
  {
    if (!this->Has(8))
    {
      return this->Fail("the file ends inside an element's header");
    }
    tag = Tag(this->U16(this->At), this->U16(this->At + 2));
    vr[0] = vr[1] = 0;
    const bool delimiter = (tag >> 16) == 0xFFFE;
    if (!explicitVR || delimiter)
    {
      length = this->U32(this->At + 4);
      this->At += 8;
      return true;
    }
    vr[0] = static_cast<char>(this->Bytes[this->At + 4]);
    vr[1] = static_cast<char>(this->Bytes[this->At + 5]);
    static const char* const Long[] = { "OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN",
      "UR", "UT", "UV" };
    bool isLong = false;
    for (const char* name : Long)
    {
      isLong = isLong || (vr[0] == name[0] && vr[1] == name[1]);
    }
    if (isLong)
    {
      if (!this->Has(12))
      {
        return this->Fail("the file ends inside an element's header");
      }
      length = this->U32(this->At + 8);
      this->At += 12;
    }
    else
    {
      length = this->U16(this->At + 6);
      this->At += 8;
    }
    return true;
  }

  bool Skip(std::uint32_t length)
  {
    if (!this->Has(length))
    {
      return this->Fail("the file ends inside an element");
    }
    this->At += length;
    return true;
  }

  // The items of a sequence of undefined length, up to its delimiter.
  bool SkipSequence(bool explicitVR, int depth)
  {
    if (depth > 64)
    {
      return this->Fail("sequences nested more than 64 deep");
    }
    for (;;)
    {
      std::uint32_t tag, length;
      char vr[2];
      if (!this->ElementHeader(explicitVR, tag, vr, length))
      {
        return false;
      }
      if (tag == SequenceEndTag)
      {
        return true;
      }
      if (tag != ItemTag)
      {
        return this->Fail("a sequence holds something other than items");
      }
      if (length != Undefined)
      {
        if (!this->Skip(length))
        {
          return false;
        }
        continue;
      }
      if (!this->Elements(explicitVR, depth + 1, nullptr))
      {
        return false;
      }
    }
  }

  // Elements up to the end of the bytes (top level, `header` set) or to an
  // item delimiter (inside an item of undefined length).
  bool Elements(bool explicitVR, int depth, Header* header)
  {
    while (header ? this->At < this->Size : true)
    {
      std::uint32_t tag, length;
      char vr[2];
      if (!this->ElementHeader(explicitVR, tag, vr, length))
      {
        return false;
      }
      if (!header && tag == ItemEndTag)
      {
        return true;
      }
      if (header && tag == PixelDataTag)
      {
        header->HasPixelData = true;
        header->Encapsulated = length == Undefined;
        header->PixelOffset = this->At;
        header->PixelLength = length == Undefined ? 0 : length;
        if (!header->Encapsulated && !this->Has(length))
        {
          return this->Fail("the file ends inside its Pixel Data");
        }
        return true;
      }
      if (header && (tag == SharedGroupsTag || tag == PerFrameGroupsTag))
      {
        header->FunctionalGroups = true;
      }
      if (length == Undefined)
      {
        // Only a sequence (or an UN holding one, in implicit VR) may have an
        // undefined length outside Pixel Data.
        const bool un = explicitVR && vr[0] == 'U' && vr[1] == 'N';
        if (!this->SkipSequence(un ? false : explicitVR, depth + 1))
        {
          return false;
        }
        continue;
      }
      if (!this->Has(length))
      {
        return this->Fail("the file ends inside an element");
      }
      const char* ruleVR = header ? RuleVR(tag) : nullptr;
      if (ruleVR && explicitVR && (vr[0] != ruleVR[0] || vr[1] != ruleVR[1]))
      {
        // What DCMTK makes of an attribute under another VR is its own: not guessed here.
        char name[16];
        std::snprintf(name, sizeof(name), "(%04X,%04X)", tag >> 16, tag & 0xFFFFu);
        return this->Fail(std::string("attribute ") + name + " has VR \"" + std::string(vr, 2) +
          "\", not " + ruleVR);
      }
      if (ruleVR && ruleVR[0] == 'U' && ruleVR[1] == 'S')
      {
        if (length != 2)
        {
          return this->Fail("an unsigned short attribute of " + std::to_string(length) + " bytes");
        }
        header->Short[tag] = this->U16(this->At);
      }
      else if (ruleVR)
      {
        header->Text[tag] = TrimmedText(this->Bytes + this->At, length);
      }
      this->At += length;
    }
    return true;
  }
};

// The group 2 and the data set of one file, up to Pixel Data.
HeaderStatus ParseHeader(
  const unsigned char* bytes, std::size_t size, Header& header, std::string& why)
{
  if (size < 132 || std::memcmp(bytes + 128, "DICM", 4) != 0)
  {
    return HeaderStatus::NotImage;
  }
  Parser parser(bytes, size);
  parser.At = 132;
  // Group 2, always explicit VR little endian.
  while (parser.Has(8) && parser.U16(parser.At) == 0x0002)
  {
    std::uint32_t tag, length;
    char vr[2];
    if (!parser.ElementHeader(true, tag, vr, length) || length == Undefined || !parser.Has(length))
    {
      why = parser.Why.empty() ? "its File Meta Information is damaged" : parser.Why;
      return HeaderStatus::Unreadable;
    }
    if (tag == TransferSyntaxTag)
    {
      header.TransferSyntaxUID = TrimmedText(bytes + parser.At, length);
    }
    parser.At += length;
  }
  const std::string& syntax = header.TransferSyntaxUID;
  if (syntax != ImplicitLittle && syntax != ExplicitLittle)
  {
    // Its data set is not parsed: the caller refuses the file by its syntax.
    return HeaderStatus::Image;
  }
  if (!parser.Elements(syntax == ExplicitLittle, 0, &header))
  {
    why = parser.Why;
    return HeaderStatus::Unreadable;
  }
  if (!header.HasPixelData || !header.Short.count(RowsTag) || !header.Short.count(ColumnsTag))
  {
    return HeaderStatus::NotImage;
  }
  return HeaderStatus::Image;
}

// ---------------------------------------------------------------------------
// The page's series: the shared rules (below, public) over the parser's attributes, for
// single-frame files.

struct Instance : DICOMImageFormat
{
  const unsigned char* Bytes = nullptr;
  double SliceThickness = 0.0;
  std::uint64_t PixelOffset = 0;
  std::uint64_t PixelLength = 0;
  DICOMSlice Slice; // the one slice
};

// The attributes the rules use, as DCMTK's findAndGet* gives them.
void Describe(const Header& header, Instance& instance)
{
  auto text = [&header](std::uint32_t tag, std::string& value)
  {
    const auto found = header.Text.find(tag);
    if (found == header.Text.end())
    {
      return false;
    }
    value = found->second;
    return true;
  };
  auto number = [&header](std::uint32_t tag, std::uint16_t& value)
  {
    const auto found = header.Short.find(tag);
    if (found == header.Short.end())
    {
      return false;
    }
    value = found->second;
    return true;
  };
  std::string value;
  if (text(SeriesUIDTag, value))
  {
    instance.SeriesUID = value;
  }
  if (text(SeriesDescriptionTag, value))
  {
    instance.SeriesDescription = value;
  }
  number(RowsTag, instance.Rows);
  number(ColumnsTag, instance.Columns);
  number(BitsAllocatedTag, instance.BitsAllocated);
  if (!number(BitsStoredTag, instance.BitsStored))
  {
    instance.BitsStored = instance.BitsAllocated;
  }
  if (!number(HighBitTag, instance.HighBit))
  {
    instance.HighBit = instance.BitsStored > 0 ? instance.BitsStored - 1 : 0;
  }
  number(RepresentationTag, instance.PixelRepresentation);
  if (!number(SamplesTag, instance.SamplesPerPixel))
  {
    instance.SamplesPerPixel = 1;
  }
  if (text(PhotometricTag, value))
  {
    instance.Photometric = value;
  }
  double read[6];
  if (text(InstanceNumberTag, value) && NumberAt(value, 0, read[0]) &&
    read[0] == std::floor(read[0]) && std::abs(read[0]) < 2147483648.0)
  {
    instance.Slice.InstanceNumber = static_cast<long>(read[0]);
  }
  const bool hasThickness = text(SliceThicknessTag, value);
  if (Doubles(value, hasThickness, read, 1))
  {
    instance.SliceThickness = read[0];
  }
  bool present = text(PositionTag, value);
  instance.Slice.HasPosition = Doubles(value, present, instance.Slice.Position, 3);
  present = text(OrientationTag, value);
  instance.Slice.HasOrientation = Doubles(value, present, instance.Slice.Orientation, 6);
  present = text(PixelSpacingTag, value);
  instance.Slice.HasPixelSpacing = Doubles(value, present, instance.Slice.PixelSpacing, 2);
  present = text(SlopeTag, value);
  if (Doubles(value, present, read, 1))
  {
    instance.Slice.Slope = read[0];
  }
  present = text(InterceptTag, value);
  if (Doubles(value, present, read, 1))
  {
    instance.Slice.Intercept = read[0];
  }
  instance.PixelOffset = header.PixelOffset;
  instance.PixelLength = header.PixelLength;
}

std::string CheckInstances(const std::vector<const Instance*>& instances)
{
  const Instance& first = *instances.front();
  for (const Instance* instance : instances)
  {
    std::string error = CheckDICOMImageFormat(*instance);
    if (error.empty() && instance->PixelLength < DICOMPixelBytes(*instance))
    {
      error = DICOMShortPixelData(*instance, instance->PixelLength);
    }
    if (error.empty())
    {
      error = CheckDICOMImageLikeFirst(*instance, first);
    }
    if (!error.empty())
    {
      return error;
    }
  }
  return std::string();
}

// The vector operations in the order vtkMath does them, so that the
// placement is the reader's to the last bit.
double Dot(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double Normalize(double v[3])
{
  const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (length != 0.0)
  {
    for (int c = 0; c < 3; ++c)
    {
      v[c] /= length;
    }
  }
  return length;
}

void Cross(const double a[3], const double b[3], double c[3])
{
  const double x = a[1] * b[2] - a[2] * b[1];
  const double y = a[2] * b[0] - a[0] * b[2];
  const double z = a[0] * b[1] - a[1] * b[0];
  c[0] = x;
  c[1] = y;
  c[2] = z;
}

struct SliceStack
{
  std::vector<const DICOMSlice*> Slices; // in increasing position
  std::vector<double> Distances;         // along the normal
  double Row[3] = { 1, 0, 0 };
  double Column[3] = { 0, 1, 0 };
  double Normal[3] = { 0, 0, 1 };
  double Median = 0.0;
  std::vector<std::string> Uneven;
  bool ValidPixelSpacing = false;

  std::string Where(std::size_t k) const
  {
    return Number(this->Distances[k]) + " mm (" + this->Slices[k]->Name + ")";
  }
};

std::string CheckSlices(SliceStack& stack)
{
  const DICOMSlice& reference = *stack.Slices.front();
  const std::string& referenceName = reference.Name;
  const bool single = stack.Slices.size() == 1;
  if (reference.HasOrientation)
  {
    std::copy(reference.Orientation, reference.Orientation + 3, stack.Row);
    std::copy(reference.Orientation + 3, reference.Orientation + 6, stack.Column);
    const double rowLength = Normalize(stack.Row);
    const double columnLength = Normalize(stack.Column);
    if (std::abs(rowLength - 1.0) > 1e-3 || std::abs(columnLength - 1.0) > 1e-3 ||
      std::abs(Dot(stack.Row, stack.Column)) > 1e-3)
    {
      return referenceName + ": Image Orientation (Patient) is not two orthogonal unit vectors";
    }
  }
  Cross(stack.Row, stack.Column, stack.Normal);
  for (const DICOMSlice* slice : stack.Slices)
  {
    const std::string& name = slice->Name;
    if (!single && !slice->HasPosition)
    {
      return name + ": no Image Position (Patient): the slices' order and spacing are unknown";
    }
    if (!single && !slice->HasOrientation)
    {
      return name + ": no Image Orientation (Patient): the slices' order and spacing are unknown";
    }
    for (int c = 0; c < 6 && slice->HasOrientation; ++c)
    {
      if (std::abs(slice->Orientation[c] - reference.Orientation[c]) > 1e-4)
      {
        std::string a, b;
        for (int d = 0; d < 6; ++d)
        {
          a += (d ? "\\" : "") + Number(slice->Orientation[d]);
          b += (d ? "\\" : "") + Number(reference.Orientation[d]);
        }
        return name + ": Image Orientation (Patient) " + a + ", but " + referenceName + " has " +
          b + ": slices of different orientations are not read";
      }
    }
    if (slice->HasPixelSpacing != reference.HasPixelSpacing ||
      std::abs(slice->PixelSpacing[0] - reference.PixelSpacing[0]) > 1e-4 ||
      std::abs(slice->PixelSpacing[1] - reference.PixelSpacing[1]) > 1e-4)
    {
      return name + ": Pixel Spacing " + Number(slice->PixelSpacing[0]) + "\\" +
        Number(slice->PixelSpacing[1]) + ", but " + referenceName + " has " +
        Number(reference.PixelSpacing[0]) + "\\" + Number(reference.PixelSpacing[1]) +
        ": slices of different pixel spacings are not read";
    }
    if (slice->Slope == 0.0)
    {
      return name + ": Rescale Slope 0";
    }
  }
  stack.ValidPixelSpacing =
    reference.HasPixelSpacing && reference.PixelSpacing[0] > 0.0 && reference.PixelSpacing[1] > 0.0;
  return std::string();
}

std::string StackSlices(SliceStack& stack)
{
  std::string error = CheckSlices(stack);
  if (!error.empty())
  {
    return error;
  }
  const double* normal = stack.Normal;
  std::stable_sort(stack.Slices.begin(), stack.Slices.end(),
    [normal](const DICOMSlice* a, const DICOMSlice* b)
    {
      const double da = Dot(a->Position, normal);
      const double db = Dot(b->Position, normal);
      return da != db ? da < db : a->InstanceNumber < b->InstanceNumber;
    });
  const std::size_t count = stack.Slices.size();
  for (const DICOMSlice* slice : stack.Slices)
  {
    stack.Distances.push_back(Dot(slice->Position, normal));
  }
  if (count < 2)
  {
    return std::string();
  }
  std::vector<double> steps(count - 1);
  for (std::size_t k = 0; k + 1 < count; ++k)
  {
    steps[k] = stack.Distances[k + 1] - stack.Distances[k];
  }
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  stack.Median = sorted[sorted.size() / 2];
  const double tolerance = 0.01 * stack.Median;
  for (std::size_t k = 0; k + 1 < count; ++k)
  {
    if (!(steps[k] > std::max(tolerance, 1e-6)))
    {
      return "two slices at the same position along the normal, " + stack.Where(k) + " and " +
        stack.Where(k + 1) + ": duplicate slices are not read";
    }
  }
  const double* origin = stack.Slices.front()->Position;
  const double* pixel = stack.Slices.front()->PixelSpacing;
  const double lateral = std::max(1e-3, 0.01 * std::min(pixel[0], pixel[1]));
  for (std::size_t k = 1; k < count; ++k)
  {
    double offset[3];
    for (int c = 0; c < 3; ++c)
    {
      offset[c] = stack.Slices[k]->Position[c] - origin[c];
    }
    const double along = Dot(offset, normal);
    for (int c = 0; c < 3; ++c)
    {
      offset[c] -= along * normal[c];
    }
    const double off =
      std::sqrt(offset[0] * offset[0] + offset[1] * offset[1] + offset[2] * offset[2]);
    if (off > lateral)
    {
      return stack.Slices[k]->Name + ": its Image Position (Patient) is " + Number(off) +
        " mm off the line through " + stack.Slices[0]->Name +
        " along the slice normal (a gantry tilt or a sheared stack): not read";
    }
  }
  for (std::size_t k = 0; k + 1 < count; ++k)
  {
    if (std::abs(steps[k] - stack.Median) <= tolerance)
    {
      continue;
    }
    const double whole = std::round(steps[k] / stack.Median);
    const std::string between = " mm between " + stack.Where(k) + " and " + stack.Where(k + 1);
    if (whole >= 2.0 && std::abs(steps[k] - whole * stack.Median) <= tolerance)
    {
      const int missing = static_cast<int>(whole) - 1;
      stack.Uneven.push_back("a gap of " + Number(steps[k]) + between + " (" +
        std::to_string(missing) + (missing == 1 ? " slice missing)" : " slices missing)"));
    }
    else
    {
      stack.Uneven.push_back("a step of " + Number(steps[k]) + between);
    }
  }
  return std::string();
}

// The series' files in the stack's order, for decoding.
struct Stack
{
  std::vector<const Instance*> Slices; // in increasing position
};

// Stored values: the little endian words of the file's pixel data.
template <typename Stored>
void Unpack(const Instance& instance, std::size_t count, Stored* out, std::int64_t& least,
  std::int64_t& greatest)
{
  const unsigned char* raw = instance.Bytes + instance.PixelOffset;
  if (instance.BitsAllocated == 16)
  {
    UnpackDICOMValues(
      instance, count,
      [raw](std::size_t p)
      { return static_cast<std::uint32_t>(raw[2 * p] | (raw[2 * p + 1] << 8)); },
      out, least, greatest);
  }
  else
  {
    UnpackDICOMValues(
      instance, count, [raw](std::size_t p) { return static_cast<std::uint32_t>(raw[p]); }, out,
      least, greatest);
  }
}

std::size_t SizeOf(ScalarType type)
{
  switch (type)
  {
    case ScalarType::Int8:
    case ScalarType::UInt8:
      return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16:
      return 2;
    case ScalarType::Int32:
    case ScalarType::UInt32:
    case ScalarType::Float32:
      return 4;
    default:
      return 8;
  }
}

template <typename In>
void Rescale(const In* in, void* out, ScalarType type, std::size_t sliceSize,
  const std::vector<double>& slopes, const std::vector<double>& intercepts)
{
  switch (type)
  {
    case ScalarType::Int8:
      RescaleDICOMSlices(in, static_cast<std::int8_t*>(out), sliceSize, slopes, intercepts);
      break;
    case ScalarType::UInt8:
      RescaleDICOMSlices(in, static_cast<std::uint8_t*>(out), sliceSize, slopes, intercepts);
      break;
    case ScalarType::Int16:
      RescaleDICOMSlices(in, static_cast<std::int16_t*>(out), sliceSize, slopes, intercepts);
      break;
    case ScalarType::UInt16:
      RescaleDICOMSlices(in, static_cast<std::uint16_t*>(out), sliceSize, slopes, intercepts);
      break;
    case ScalarType::Int32:
      RescaleDICOMSlices(in, static_cast<std::int32_t*>(out), sliceSize, slopes, intercepts);
      break;
    case ScalarType::UInt32:
      RescaleDICOMSlices(in, static_cast<std::uint32_t*>(out), sliceSize, slopes, intercepts);
      break;
    case ScalarType::Float32:
      RescaleDICOMSlices(in, static_cast<float*>(out), sliceSize, slopes, intercepts);
      break;
    case ScalarType::Float64:
      RescaleDICOMSlices(in, static_cast<double*>(out), sliceSize, slopes, intercepts);
      break;
  }
}

template <typename Stored>
std::string Decode(const Stack& stack, DICOMSeriesVolume& volume)
{
  const Instance& first = *stack.Slices.front();
  const std::size_t count = stack.Slices.size();
  const std::size_t sliceSize = static_cast<std::size_t>(first.Rows) * first.Columns;
  std::vector<Stored> stored(sliceSize * count);
  std::vector<std::int64_t> least(count), greatest(count);
  for (std::size_t k = 0; k < count; ++k)
  {
    least[k] = std::numeric_limits<std::int64_t>::max();
    greatest[k] = std::numeric_limits<std::int64_t>::min();
    Unpack(*stack.Slices[k], sliceSize, stored.data() + k * sliceSize, least[k], greatest[k]);
  }
  std::vector<double> slopes(count), intercepts(count);
  for (std::size_t k = 0; k < count; ++k)
  {
    slopes[k] = stack.Slices[k]->Slice.Slope;
    intercepts[k] = stack.Slices[k]->Slice.Intercept;
  }
  const ScalarType storedType = ScalarTypeOf<Stored>();
  const ScalarType outputType = DICOMRescaledType(slopes, intercepts, least, greatest);
  volume.Type = outputType;
  if (outputType != storedType || slopes[0] != 1.0 || intercepts[0] != 0.0)
  {
    volume.Values.resize(sliceSize * count * SizeOf(outputType));
    Rescale(stored.data(), volume.Values.data(), outputType, sliceSize, slopes, intercepts);
  }
  else
  {
    volume.Values.resize(sliceSize * count * sizeof(Stored));
    std::memcpy(volume.Values.data(), stored.data(), volume.Values.size());
  }
  return std::string();
}

const struct
{
  const char* UID;
  const char* Name;
} SyntaxNames[] = {
  { "1.2.840.10008.1.2", "Implicit VR Little Endian" },
  { "1.2.840.10008.1.2.1", "Explicit VR Little Endian" },
  { "1.2.840.10008.1.2.1.99", "Deflated Explicit VR Little Endian" },
  { "1.2.840.10008.1.2.2", "Explicit VR Big Endian" },
  { "1.2.840.10008.1.2.4.50", "JPEG Baseline" },
  { "1.2.840.10008.1.2.4.51", "JPEG Extended" },
  { "1.2.840.10008.1.2.4.57", "JPEG Lossless" },
  { "1.2.840.10008.1.2.4.70", "JPEG Lossless, first-order prediction" },
  { "1.2.840.10008.1.2.4.80", "JPEG-LS Lossless" },
  { "1.2.840.10008.1.2.4.81", "JPEG-LS Lossy" },
  { "1.2.840.10008.1.2.4.90", "JPEG 2000 (Lossless only)" },
  { "1.2.840.10008.1.2.4.91", "JPEG 2000" },
  { "1.2.840.10008.1.2.5", "RLE Lossless" },
};

std::string ReadSeries(
  const std::string& folder, std::vector<DICOMFileBytes>& files, DICOMSeriesVolume& volume)
{
  std::sort(files.begin(), files.end(),
    [](const DICOMFileBytes& a, const DICOMFileBytes& b) { return a.Name < b.Name; });
  // 1. Scan.
  std::vector<Instance> images;
  for (const DICOMFileBytes& file : files)
  {
    Header header;
    std::string why;
    const HeaderStatus status = ParseHeader(file.Bytes, file.Size, header, why);
    if (status == HeaderStatus::NotImage)
    {
      continue;
    }
    // The reader skips a file DCMTK cannot parse; whether DCMTK parses one this parser cannot is
    // not known here, so the page refuses the folder rather than read it without that file.
    if (status == HeaderStatus::Unreadable)
    {
      return file.Name + ": a DICOM file that is not read in the page (" + why +
        "); open the folder through the server";
    }
    const std::string& syntax = header.TransferSyntaxUID;
    if (syntax != ImplicitLittle && syntax != ExplicitLittle)
    {
      const char* name = DICOMTransferSyntaxName(syntax);
      return file.Name + ": transfer syntax " + (name[0] ? "\"" + std::string(name) + "\" " : "") +
        "(" + (syntax.empty() ? std::string("none given") : syntax) +
        ") is not read in the page (only uncompressed little endian files are: implicit or " +
        "explicit VR); open the folder through the server";
    }
    const auto frames = header.Text.find(FramesTag);
    double frameCount = 1.0;
    if (header.FunctionalGroups ||
      (frames != header.Text.end() && NumberAt(frames->second, 0, frameCount) && frameCount > 1.0))
    {
      return file.Name + ": a multi-frame (enhanced) image is not read in the page; open the " +
        "folder through the server";
    }
    Instance instance;
    instance.Name = file.Name;
    instance.Bytes = file.Bytes;
    Describe(header, instance);
    images.push_back(std::move(instance));
  }
  if (images.empty())
  {
    return folder + ": no DICOM image files in the folder";
  }

  // 2. Choose the series with the most slices.
  std::vector<const DICOMImageFormat*> formats;
  for (const Instance& image : images)
  {
    formats.push_back(&image);
  }
  const std::vector<DICOMSeriesGroup> all = GroupDICOMSeries(formats);
  const DICOMSeriesGroup& read = all.front();
  if (all.size() > 1)
  {
    std::vector<std::string> others;
    for (std::size_t s = 1; s < all.size(); ++s)
    {
      others.push_back(DescribeDICOMSeries(all[s]));
    }
    volume.Warnings.push_back(folder + ": the folder holds " + std::to_string(all.size()) +
      " series; read " + DescribeDICOMSeries(read) +
      ", the series with the most slices; not read: " + JoinList(others, "; "));
  }

  // 3-5. Check the files and the slices; order them along the normal.
  std::vector<const Instance*> instances;
  for (std::size_t i : read.Instances)
  {
    instances.push_back(&images[i]);
  }
  std::string error = CheckInstances(instances);
  std::vector<DICOMSlice> slices;
  for (const Instance* instance : instances)
  {
    slices.push_back(instance->Slice);
    slices.back().Name = instance->Name;
  }
  DICOMStack sorted;
  if (error.empty())
  {
    error = StackDICOMSlices(slices, sorted);
  }
  if (!error.empty())
  {
    return error;
  }
  Stack stack;
  for (std::size_t k : sorted.Order)
  {
    stack.Slices.push_back(instances[k]);
  }
  const Instance& first = *instances.front();
  if (!sorted.ValidPixelSpacing)
  {
    volume.Warnings.push_back(
      first.Name + ": no valid Pixel Spacing; 1 mm between rows and columns assumed");
  }
  if (!sorted.Uneven.empty())
  {
    return "the slices are not evenly spaced (median step " + Number(sorted.Median) +
      " mm): " + DICOMUnevenList(sorted.Uneven) + ". The page does not resample them.";
  }

  // 6-7. Decode and rescale.
  const bool isSigned = first.PixelRepresentation == 1;
  if (first.BitsAllocated == 8)
  {
    error = isSigned ? Decode<std::int8_t>(stack, volume) : Decode<std::uint8_t>(stack, volume);
  }
  else
  {
    error = isSigned ? Decode<std::int16_t>(stack, volume) : Decode<std::uint16_t>(stack, volume);
  }
  if (!error.empty())
  {
    return error;
  }

  // Placement.
  const std::size_t count = stack.Slices.size();
  const std::vector<double>& distances = sorted.Distances;
  const double step = count > 1 ? (distances.back() - distances.front()) / (count - 1) : 0.0;
  volume.SeriesUID = read.UID;
  volume.Dimensions[0] = first.Columns;
  volume.Dimensions[1] = first.Rows;
  volume.Dimensions[2] = static_cast<int>(count);
  PlaceDICOMStack(sorted, stack.Slices.front()->Slice, count, step, first.SliceThickness,
    volume.Origin, volume.Direction, volume.Spacing);
  return std::string();
}
} // namespace

std::string StackDICOMSlices(const std::vector<DICOMSlice>& slices, DICOMStack& stack)
{
  stack = DICOMStack();
  if (slices.empty())
  {
    return "no slices";
  }
  SliceStack work;
  for (const DICOMSlice& slice : slices)
  {
    work.Slices.push_back(&slice);
  }
  const std::string error = StackSlices(work);
  if (!error.empty())
  {
    return error;
  }
  for (const DICOMSlice* slice : work.Slices)
  {
    stack.Order.push_back(static_cast<std::size_t>(slice - slices.data()));
  }
  stack.Distances = work.Distances;
  std::copy(work.Row, work.Row + 3, stack.Row);
  std::copy(work.Column, work.Column + 3, stack.Column);
  std::copy(work.Normal, work.Normal + 3, stack.Normal);
  stack.Median = work.Median;
  stack.Uneven = work.Uneven;
  stack.ValidPixelSpacing = work.ValidPixelSpacing;
  return std::string();
}

ScalarType DICOMIntegerType(double least, double greatest)
{
  if (least >= 0.0)
  {
    if (greatest <= 255.0)
    {
      return ScalarType::UInt8;
    }
    if (greatest <= 65535.0)
    {
      return ScalarType::UInt16;
    }
    if (greatest <= 4294967295.0)
    {
      return ScalarType::UInt32;
    }
    return ScalarType::Float64;
  }
  if (least >= -128.0 && greatest <= 127.0)
  {
    return ScalarType::Int8;
  }
  if (least >= -32768.0 && greatest <= 32767.0)
  {
    return ScalarType::Int16;
  }
  if (least >= -2147483648.0 && greatest <= 2147483647.0)
  {
    return ScalarType::Int32;
  }
  return ScalarType::Float64;
}

ScalarType DICOMRescaledType(const std::vector<double>& slopes,
  const std::vector<double>& intercepts, const std::vector<std::int64_t>& least,
  const std::vector<std::int64_t>& greatest)
{
  bool uniform = true, integral = true;
  double low = 0.0, high = 0.0;
  for (std::size_t k = 0; k < slopes.size(); ++k)
  {
    uniform = uniform && slopes[k] == slopes[0] && intercepts[k] == intercepts[0];
    integral =
      integral && slopes[k] == std::round(slopes[k]) && intercepts[k] == std::round(intercepts[k]);
    const double a = slopes[k] * static_cast<double>(least[k]) + intercepts[k];
    const double b = slopes[k] * static_cast<double>(greatest[k]) + intercepts[k];
    low = k == 0 ? std::min(a, b) : std::min(low, std::min(a, b));
    high = k == 0 ? std::max(a, b) : std::max(high, std::max(a, b));
  }
  // Float holds every stored value (at most 16 bits) times a slope exactly
  // when the slope has a short binary fraction, and to 24 bits otherwise.
  return (!uniform || !integral) ? ScalarType::Float32 : DICOMIntegerType(low, high);
}

std::uint64_t DICOMPixelBytes(const DICOMImageFormat& image)
{
  return static_cast<std::uint64_t>(image.Rows) * image.Columns * image.Frames *
    (image.BitsAllocated / 8);
}

std::string DICOMShortPixelData(const DICOMImageFormat& image, std::uint64_t have)
{
  return image.Name + ": Pixel Data holds " + std::to_string(have) + " bytes, " +
    std::to_string(DICOMPixelBytes(image)) + " expected (" + std::to_string(image.Columns) + " x " +
    std::to_string(image.Rows) + " x " + std::to_string(image.Frames) + " frame(s) x " +
    std::to_string(image.BitsAllocated / 8) + " byte(s))";
}

std::string CheckDICOMImageFormat(const DICOMImageFormat& image)
{
  const std::string& name = image.Name;
  if (image.SamplesPerPixel != 1 ||
    (image.Photometric != "MONOCHROME1" && image.Photometric != "MONOCHROME2"))
  {
    return name + ": " + std::to_string(image.SamplesPerPixel) + " sample(s) per pixel, " +
      "Photometric Interpretation \"" + image.Photometric +
      "\": only greyscale (MONOCHROME1/2) images are read";
  }
  if (image.BitsAllocated != 8 && image.BitsAllocated != 16)
  {
    return name + ": Bits Allocated " + std::to_string(image.BitsAllocated) +
      " is not read (8 or 16)";
  }
  if (image.BitsStored == 0 || image.BitsStored > image.BitsAllocated ||
    image.HighBit + 1 < image.BitsStored || image.HighBit >= image.BitsAllocated)
  {
    return name + ": Bits Stored " + std::to_string(image.BitsStored) + " and High Bit " +
      std::to_string(image.HighBit) + " do not fit Bits Allocated " +
      std::to_string(image.BitsAllocated);
  }
  if (image.Rows == 0 || image.Columns == 0)
  {
    return name + ": an image of " + std::to_string(image.Columns) + " x " +
      std::to_string(image.Rows) + " pixels";
  }
  return std::string();
}

std::string CheckDICOMImageLikeFirst(const DICOMImageFormat& image, const DICOMImageFormat& first)
{
  if (image.Rows != first.Rows || image.Columns != first.Columns)
  {
    return image.Name + ": " + std::to_string(image.Columns) + " x " + std::to_string(image.Rows) +
      " pixels, but " + first.Name + " has " + std::to_string(first.Columns) + " x " +
      std::to_string(first.Rows) + ": slices of different sizes are not read";
  }
  if (image.BitsAllocated != first.BitsAllocated ||
    image.PixelRepresentation != first.PixelRepresentation)
  {
    return image.Name + ": pixel format " + std::to_string(image.BitsAllocated) + " bits " +
      (image.PixelRepresentation ? "signed" : "unsigned") + ", but " + first.Name + " has " +
      std::to_string(first.BitsAllocated) + " bits " +
      (first.PixelRepresentation ? "signed" : "unsigned") +
      ": slices of different pixel formats are not read";
  }
  return std::string();
}

std::vector<DICOMSeriesGroup> GroupDICOMSeries(const std::vector<const DICOMImageFormat*>& images)
{
  std::vector<DICOMSeriesGroup> all;
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < images.size(); ++i)
  {
    const DICOMImageFormat& image = *images[i];
    auto found = index.find(image.SeriesUID);
    if (found == index.end())
    {
      found = index.emplace(image.SeriesUID, all.size()).first;
      all.emplace_back();
      all.back().UID = image.SeriesUID;
      all.back().Description = image.SeriesDescription;
    }
    all[found->second].Instances.push_back(i);
    all[found->second].Slices += image.Frames;
  }
  std::stable_sort(all.begin(), all.end(),
    [](const DICOMSeriesGroup& a, const DICOMSeriesGroup& b) { return a.Slices > b.Slices; });
  return all;
}

std::string DescribeDICOMSeries(const DICOMSeriesGroup& series)
{
  std::string text = series.UID.empty() ? std::string("(no Series Instance UID)") : series.UID;
  text += " (";
  if (!series.Description.empty())
  {
    text += "\"" + series.Description + "\", ";
  }
  text += std::to_string(series.Slices) + (series.Slices == 1 ? " slice)" : " slices)");
  return text;
}

void PlaceDICOMStack(const DICOMStack& stack, const DICOMSlice& first, std::size_t slices,
  double step, double thickness, double origin[3], double direction[9], double spacing[3])
{
  for (int c = 0; c < 3; ++c)
  {
    origin[c] = first.HasPosition ? first.Position[c] : 0.0;
    direction[3 * c + 0] = stack.Row[c];
    direction[3 * c + 1] = stack.Column[c];
    direction[3 * c + 2] = stack.Normal[c];
  }
  spacing[0] = stack.ValidPixelSpacing ? first.PixelSpacing[1] : 1.0;
  spacing[1] = stack.ValidPixelSpacing ? first.PixelSpacing[0] : 1.0;
  spacing[2] = slices > 1 ? step : (thickness > 0.0 ? thickness : 1.0);
}

std::string DICOMUnevenList(const std::vector<std::string>& uneven)
{
  std::vector<std::string> listed(
    uneven.begin(), uneven.begin() + std::min<std::size_t>(uneven.size(), 5));
  if (uneven.size() > 5)
  {
    listed.push_back("and " + std::to_string(uneven.size() - 5) + " more");
  }
  return JoinList(listed, "; ");
}

const char* DICOMTransferSyntaxName(const std::string& uid)
{
  for (const auto& entry : SyntaxNames)
  {
    if (uid == entry.UID)
    {
      return entry.Name;
    }
  }
  return "";
}

std::string ReadDICOMSeries(
  const std::string& folder, std::vector<DICOMFileBytes> files, DICOMSeriesVolume& volume)
{
  volume = DICOMSeriesVolume();
  std::string error;
  try
  {
    error = ReadSeries(folder, files, volume);
  }
  catch (const std::bad_alloc&)
  {
    error = "out of memory while reading the series";
  }
  if (!error.empty())
  {
    std::vector<std::string> warnings = std::move(volume.Warnings);
    volume = DICOMSeriesVolume();
    volume.Warnings = std::move(warnings);
  }
  return error;
}

} // namespace mediso
