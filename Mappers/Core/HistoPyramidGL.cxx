// SPDX-License-Identifier: BSD-3-Clause
#include "HistoPyramidGL.h"

#include "GLObjects.h"
#include "MedisoShaders.h"
#include "ProcessMemory.h"

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <sstream>

namespace mediso
{
namespace
{
using namespace glcore;

// The texture format of the stored volume (RGBA of the value type).
struct VolumeFormat
{
  GLenum InternalFormat, Format, Type;
  int BytesPerValue;
};

VolumeFormat VolumeFormatOf(ScalarType type)
{
  switch (type)
  {
    case ScalarType::Int8:
      return { GL_RGBA8I, GL_RGBA_INTEGER, GL_BYTE, 1 };
    case ScalarType::UInt8:
      return { GL_RGBA8UI, GL_RGBA_INTEGER, GL_UNSIGNED_BYTE, 1 };
    case ScalarType::Int16:
      return { GL_RGBA16I, GL_RGBA_INTEGER, GL_SHORT, 2 };
    case ScalarType::UInt16:
      return { GL_RGBA16UI, GL_RGBA_INTEGER, GL_UNSIGNED_SHORT, 2 };
    case ScalarType::Int32:
      return { GL_RGBA32I, GL_RGBA_INTEGER, GL_INT, 4 };
    case ScalarType::UInt32:
      return { GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT, 4 };
    default: // float, and double converted to float
      return { GL_RGBA32F, GL_RGBA, GL_FLOAT, 4 };
  }
}

int Log2(int powerOfTwo)
{
  int shift = 0;
  while ((1 << shift) < powerOfTwo)
  {
    ++shift;
  }
  return shift;
}

// Texels [offset, offset + texels) of a volume texture (x in texels of 4 values) from `data`,
// rows packed: a streamed region or a brick pool's slot. False with GL's errors.
bool UploadBox(const GLApi& gl, GLuint texture, const VolumeFormat& format, const int offset[3],
  const int texels[3], const void* data, std::string& error)
{
  const GLApi::Functions& f = gl.F();
  ScopedGLState saved(gl, 1);
  gl.TakeErrors();
  BindTextureUnit(gl, 0, GL_TEXTURE_3D, texture);
  f.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  f.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  f.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
  f.TexSubImage3D(GL_TEXTURE_3D, 0, offset[0], offset[1], offset[2], texels[0], texels[1],
    texels[2], format.Format, format.Type, data);
  error = gl.TakeErrors();
  return error.empty();
}
} // namespace

//------------------------------------------------------------------------------
// The GL objects and the CPU-side state of the pyramid.
struct HistoPyramidGL::Internals
{
  std::shared_ptr<const GLApi> GL;
  GLParallelFor Parallel;

  // The volume: a 3D texture, 4 points to a texel along x.
  Name Volume;
  ScalarType Type = ScalarType::Float32;
  int Points[3] = { 0, 0, 0 };
  // The cells that count: [OwnedFirst, OwnedEnd) per axis (every cell, or a brick's own).
  int OwnedFirst[3] = { 0, 0, 0 };
  int OwnedEnd[3] = { 0, 0, 0 };
  PyramidLayout Layout;
  // Per level-1 tile, the least and greatest value its cells read.
  VolumeTiles Tiles;

  // A brick pool (AllocatePool()): slots of 2^SlotShift points a side, the
  // slot table (one row of 3 RGBA32UI texels per slot, as the shaders read
  // it, and its CPU copy), each slot's brick tiles, the last build's counts
  // per slot, and the frame's order of the slots (64 entries to a row).
  bool Pool = false;
  int SlotShift = 0;
  int SlotsPerAxis[3] = { 0, 0, 0 };
  int DrawnCells[3] = { 0, 0, 0 };
  Name SlotTable;
  std::vector<std::array<GLuint, 12>> SlotRows;
  std::vector<VolumeTiles> SlotTiles;
  std::vector<std::uint32_t> SlotTotals;
  Name SlotOrder;
  int SlotOrderCount = 0;

  // The stored levels (index = level; 0 is empty), each a 2D atlas.
  std::vector<Name> Levels;
  bool Built = false;
  bool Queued = false; // BuildPasses() done, FinishBuild() to come
  std::uint64_t Total = 0;
  IsoThresholds Current; // of the last successful Build()
  bool ChildMasks = false;
  std::uint64_t TilesDrawn = 0;

  // The passes.
  Name FBO;
  Name TileBuffer;      // the level-1 pass's rectangles
  Name TileVertexArray; // with attribute 0 reading TileBuffer
  Name EmptyVertexArray;
  // Shared by the pyramids of one scene's bricks (ShareProgramsWith()).
  std::shared_ptr<ProgramCache> Programs = std::make_shared<ProgramCache>();

  /// A stored level's atlas layout as the shaders take it: log2 of px, py, columns.
  std::array<int, 3> Shifts(int level) const;
  /// The value type's #defines.
  std::string Declarations() const;
  /// The hook that puts HistoPyramidCommon.glsl in a shader.
  Hooks CommonHooks() const;
  /// The uniforms of HistoPyramidCommon.glsl on the bound program; the volume is on
  /// `volumeUnit`, a pool's slot table is bound to `tableUnit`.
  void SetCommonUniforms(
    Program& program, const IsoThresholds& t, int volumeUnit, int tableUnit) const;
  /// A pool slot's row of the table sent to the GPU, and its tiles placed or emptied.
  void UpdateSlot(int slot);
  int SlotCount() const
  {
    return this->SlotsPerAxis[0] * this->SlotsPerAxis[1] * this->SlotsPerAxis[2];
  }

  bool Store(ScalarType type, const void* data, const int points[3], int rowValues,
    const GLParallelFor& run, std::string& error);
  bool SlotFits(int slot, const void* values, const int points[3], std::string& error) const;
  bool StoreSlot(int slot, const void* data, const int points[3], int rowValues,
    const int placement[3], std::string& error);
  bool Target(GLuint texture, int width, int height, std::string& error);
  Program* Pass(
    const char* vertex, const char* fragment, const std::string& defines, std::string& error);
  void DrawFullScreen();
  void ReleaseLevels();
  void ReleaseAll();
};

//------------------------------------------------------------------------------
std::array<int, 3> HistoPyramidGL::Internals::Shifts(int level) const
{
  const auto packed = this->Layout.Packed(level);
  return { Log2(packed[0]), Log2(packed[1]), Log2(this->Layout.AtlasColumns(level)) };
}

std::string HistoPyramidGL::Internals::Declarations() const
{
  return ValueKindDefines(ValueKindOf(this->Type)) +
    (this->Pool ? "#define MEDISO_BRICK_POOL 1\n" : "");
}

Hooks HistoPyramidGL::Internals::CommonHooks() const
{
  return { { "HistoPyramidCommon", shaders::HistoPyramidCommon } };
}

void HistoPyramidGL::Internals::SetCommonUniforms(
  Program& program, const IsoThresholds& t, int volumeUnit, int tableUnit) const
{
  program.Set("volume", volumeUnit);
  if (this->Pool)
  {
    BindTextureUnit(*this->GL, tableUnit, GL_TEXTURE_2D, this->SlotTable.Get());
    program.Set("slotTable", tableUnit);
    program.Set("slotShift", this->SlotShift);
    program.Set3i("slotsPerAxis", this->SlotsPerAxis);
  }
  program.Set("numberOfThresholds", t.Count);
  const int cells[3] = { this->Points[0] - 1, this->Points[1] - 1, this->Points[2] - 1 };
  program.Set3i("cellDimensions", cells);
  program.Set3i("ownedCellsFirst", this->OwnedFirst);
  program.Set3i("ownedCellsEnd", this->OwnedEnd);
  switch (t.Kind)
  {
    case ValueKind::Signed:
      program.Set1iv("thresholds", t.Count, t.Ints.data());
      break;
    case ValueKind::Unsigned:
      program.Set1uiv("thresholds", t.Count, t.UInts.data());
      break;
    case ValueKind::Float:
      program.Set1fv("thresholds", t.Count, t.Floats.data());
      break;
  }
}

void HistoPyramidGL::Internals::ReleaseLevels()
{
  this->Levels.clear();
  this->Built = false;
  this->Queued = false; // and a build queued before is stale
  this->Total = 0;
  this->ChildMasks = false;
}

void HistoPyramidGL::Internals::ReleaseAll()
{
  this->ReleaseLevels();
  this->Volume.Reset();
  this->FBO.Reset();
  this->TileBuffer.Reset();
  this->TileVertexArray.Reset();
  this->EmptyVertexArray.Reset();
  // A cache shared with other pyramids stays theirs; this one lets go of it.
  if (this->Programs.use_count() > 1)
  {
    this->Programs = std::make_shared<ProgramCache>();
  }
  else
  {
    this->Programs->Clear();
  }
  this->Tiles.Clear();
  this->Pool = false;
  this->SlotShift = 0;
  std::fill(this->SlotsPerAxis, this->SlotsPerAxis + 3, 0);
  this->SlotTable.Reset();
  this->SlotOrder.Reset();
  this->SlotOrderCount = 0;
  this->SlotRows.clear();
  this->SlotTiles.clear();
  this->SlotTotals.clear();
  this->Points[0] = this->Points[1] = this->Points[2] = 0;
  this->Layout = PyramidLayout();
  this->TilesDrawn = 0;
}

//------------------------------------------------------------------------------
HistoPyramidGL::HistoPyramidGL(std::shared_ptr<const GLApi> gl)
  : Impl(new Internals)
{
  this->Impl->GL = std::move(gl);
}

HistoPyramidGL::~HistoPyramidGL() = default;

void HistoPyramidGL::Release()
{
  this->Impl->ReleaseAll();
}

bool HistoPyramidGL::HasVolume() const
{
  return static_cast<bool>(this->Impl->Volume);
}

bool HistoPyramidGL::IsBuilt() const
{
  return this->Impl->Built;
}

std::uint64_t HistoPyramidGL::GetTotal() const
{
  return this->Impl->Built ? this->Impl->Total : 0;
}

const PyramidLayout& HistoPyramidGL::GetLayout() const
{
  return this->Impl->Layout;
}

ScalarType HistoPyramidGL::GetScalarType() const
{
  return this->Impl->Type;
}

const std::vector<int>& HistoPyramidGL::GetCountedIsovalues() const
{
  static const std::vector<int> none;
  return this->Impl->Built ? this->Impl->Current.Indices : none;
}

bool HistoPyramidGL::GetLevelOneHoldsChildMasks() const
{
  return this->Impl->Built && this->Impl->ChildMasks;
}

const GLApi* HistoPyramidGL::GetGLApi() const
{
  return this->Impl->GL.get();
}

//------------------------------------------------------------------------------
HistoPyramidWalk HistoPyramidGL::GetWalk() const
{
  const Internals& impl = *this->Impl;
  HistoPyramidWalk walk;
  if (!impl.Built)
  {
    return walk;
  }
  const PyramidLayout& layout = impl.Layout;
  const int numLevels = layout.GetNumberOfLevels();
  if (impl.ChildMasks)
  {
    walk.Defines = "#define MEDISO_CHILD_MASKS 1\n";
  }
  walk.Defines += impl.Declarations();
  if (impl.Pool)
  {
    // The binary search over the frame's slots (startWalk()): its first step.
    int search = 1;
    while (2 * search < impl.SlotCount())
    {
      search *= 2;
    }
    walk.Defines += "#define MEDISO_SLOT_SEARCH " + std::to_string(search) + "\n";
  }
  std::ostringstream levels, descent;
  for (int l = 1; l + 1 < numLevels; ++l)
  {
    levels << "uniform usampler2D level" << l << ";\n";
  }
  // One step down per level, with the level's constants: with one isovalue
  // the last step reads level 1's child masks with the counts. A pool's walk
  // starts at its slot's node (startWalk() in HistoPyramidIso_vs.glsl).
  for (int l = impl.Pool ? impl.SlotShift : numLevels - 1; l >= 2; --l)
  {
    const int c = l - 1;
    const auto factor = layout.Factor(l);
    const auto span = layout.CellsPerNode(c);
    const auto shifts = impl.Shifts(c);
    const bool toMasks = impl.ChildMasks && c == 1;
    descent << (toMasks ? "  descendToMasks(level" : "  descend(level") << c << ", ivec3("
            << factor[0] << ", " << factor[1] << ", " << factor[2] << "), ivec3(" << shifts[0]
            << ", " << shifts[1] << ", " << shifts[2] << "), vec3(" << span[0] << ".0, " << span[1]
            << ".0, " << span[2] << ".0), node, index" << (toMasks ? ", nodeBits" : "") << ");\n";
  }
  walk.Hooks = impl.CommonHooks();
  walk.Hooks.emplace_back("HistoPyramidLevels", levels.str());
  walk.Hooks.emplace_back("HistoPyramidDescent", descent.str());
  walk.TextureUnits = numLevels - 1 + (impl.Pool ? 2 : 0);
  return walk;
}

void HistoPyramidGL::BindWalk(Program& program, int firstUnit) const
{
  const Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const PyramidLayout& layout = impl.Layout;
  BindTextureUnit(gl, firstUnit, GL_TEXTURE_3D, impl.Volume.Get());
  const int numLevels = layout.GetNumberOfLevels();
  impl.SetCommonUniforms(program, impl.Current, firstUnit, firstUnit + numLevels - 1);
  for (int l = 1; l + 1 < numLevels; ++l)
  {
    BindTextureUnit(gl, firstUnit + l, GL_TEXTURE_2D, impl.Levels[l].Get());
    program.Set(("level" + std::to_string(l)).c_str(), firstUnit + l);
  }
  program.Set3i("firstFactor", layout.Factor(1).data());
  if (impl.Pool)
  {
    BindTextureUnit(gl, firstUnit + numLevels, GL_TEXTURE_2D, impl.SlotOrder.Get());
    program.Set("slotOrder", firstUnit + numLevels);
    program.Set("slotOrderCount", impl.SlotOrderCount);
  }
}

std::uint64_t HistoPyramidGL::GetNumberOfTiles() const
{
  if (!this->Impl->Volume)
  {
    return 0;
  }
  const auto tiles = this->Impl->Layout.TileCounts();
  return static_cast<std::uint64_t>(tiles[0]) * tiles[1] * tiles[2];
}

std::uint64_t HistoPyramidGL::GetLastTilesDrawn() const
{
  return this->Impl->Built ? this->Impl->TilesDrawn : 0;
}

namespace
{
std::uint64_t VolumeTextureBytes(ScalarType type, const int points[3])
{
  const std::array<int, 3> texels = HistoPyramidGL::VolumeTextureSize(points);
  return static_cast<std::uint64_t>(4 * texels[0]) * texels[1] * texels[2] *
    VolumeFormatOf(type).BytesPerValue;
}
} // namespace

std::uint64_t HistoPyramidGL::GetGPUMemoryBytes() const
{
  const Internals& impl = *this->Impl;
  std::uint64_t bytes = 0;
  if (impl.Volume)
  {
    bytes += VolumeTextureBytes(impl.Type, impl.Points);
  }
  if (!impl.Levels.empty())
  {
    bytes += impl.Layout.GetStoredBytes();
  }
  return bytes;
}

std::array<int, 3> HistoPyramidGL::VolumeTextureSize(const int points[3])
{
  return { { PackedVolumeWidth(points[0]), points[1], points[2] } };
}

std::uint64_t HistoPyramidGL::EstimateGPUMemoryBytes(ScalarType type, const int points[3])
{
  const int cells[3] = { std::max(1, points[0] - 1), std::max(1, points[1] - 1),
    std::max(1, points[2] - 1) };
  return VolumeTextureBytes(type, points) + PyramidLayout(cells).GetStoredBytes();
}

//------------------------------------------------------------------------------
namespace
{
// Whether a volume of `points` can be a pyramid's volume on `gl`'s context: "" or why not.
std::string CheckVolumeSize(const GLApi& gl, const int points[3])
{
  if (points[0] < 2 || points[1] < 2 || points[2] < 2)
  {
    return "the volume must have at least 2 points per axis, not " + std::to_string(points[0]) +
      "x" + std::to_string(points[1]) + "x" + std::to_string(points[2]);
  }
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  const PyramidLayout layout(cells);
  const int width = PackedVolumeWidth(points[0]);
  if (std::max({ width, points[1], points[2] }) > gl.GetMax3DTextureSize())
  {
    return "the " + std::to_string(points[0]) + "x" + std::to_string(points[1]) + "x" +
      std::to_string(points[2]) + " volume (a " + std::to_string(width) + "x" +
      std::to_string(points[1]) + "x" + std::to_string(points[2]) +
      " texture) exceeds GL_MAX_3D_TEXTURE_SIZE " + std::to_string(gl.GetMax3DTextureSize());
  }
  for (int l = 1; l < layout.GetNumberOfLevels(); ++l)
  {
    const auto atlas = layout.AtlasSize(l);
    if (std::max(atlas[0], atlas[1]) > gl.GetMaxTextureSize())
    {
      return "level " + std::to_string(l) + " of the pyramid (a " + std::to_string(atlas[0]) +
        "x" + std::to_string(atlas[1]) + " texture) exceeds GL_MAX_TEXTURE_SIZE " +
        std::to_string(gl.GetMaxTextureSize());
    }
  }
  return "";
}
} // namespace

bool HistoPyramidGL::UploadVolume(ScalarType type, const void* values, const int points[3],
  const GLParallelFor& parallel, std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  if (!values || !points)
  {
    error = "no volume given";
    return false;
  }
  error = CheckVolumeSize(gl, points);
  if (!error.empty())
  {
    return false;
  }
  const int width = PackedVolumeWidth(points[0]);
  const GLParallelFor run = SerialIfEmpty(parallel);
  const std::int64_t numPoints = static_cast<std::int64_t>(points[0]) * points[1] * points[2];
  const VolumeFormat format = VolumeFormatOf(type);

  // The CPU-side copies the upload makes (doubles converted to float, rows
  // padded to whole texels) must fit in what the process may still allocate;
  // a host then falls back with the reason instead of aborting.
  std::uint64_t staging = type == ScalarType::Float64 ? 4 * static_cast<std::uint64_t>(numPoints) : 0;
  if (points[0] % 4 != 0)
  {
    staging += static_cast<std::uint64_t>(4 * width) * format.BytesPerValue * points[1] * points[2];
  }
  if (staging > 0 && !FitsInProcessMemory(staging, "the volume's copy for the GPU upload", error))
  {
    return false;
  }

  // Double data is converted to float; every other type goes up as it is.
  std::vector<float> converted;
  const void* data = values;
  if (type == ScalarType::Float64)
  {
    try
    {
      converted.resize(static_cast<std::size_t>(numPoints));
    }
    catch (const std::bad_alloc&)
    {
      error = "memory ran out while copying the volume for the GPU upload";
      return false;
    }
    const double* d = static_cast<const double*>(values);
    run(0, numPoints,
      [&](std::int64_t begin, std::int64_t end)
      {
        for (std::int64_t i = begin; i < end; ++i)
        {
          converted[i] = static_cast<float>(d[i]);
        }
      });
    data = converted.data();
  }
  std::vector<unsigned char> packed;
  if (points[0] % 4 != 0)
  {
    try
    {
      packed = PackVolumeRows(data, points, format.BytesPerValue, run);
    }
    catch (const std::bad_alloc&)
    {
      error = "memory ran out while copying the volume for the GPU upload";
      return false;
    }
  }
  return impl.Store(type, packed.empty() ? data : packed.data(), points,
    packed.empty() ? points[0] : 4 * width, run, error);
}

bool HistoPyramidGL::UploadPackedVolume(ScalarType type, const void* packedRows,
  const int points[3], const GLParallelFor& parallel, std::string& error)
{
  Internals& impl = *this->Impl;
  if (!packedRows || !points)
  {
    error = "no volume given";
    return false;
  }
  if (type == ScalarType::Float64)
  {
    error = "packed rows hold the texture's values, and a double volume's texture holds floats";
    return false;
  }
  error = CheckVolumeSize(*impl.GL, points);
  if (!error.empty())
  {
    return false;
  }
  return impl.Store(
    type, packedRows, points, 4 * PackedVolumeWidth(points[0]), SerialIfEmpty(parallel), error);
}

// The volume texture from `data`, the texture's values with rows of `rowValues` (a multiple
// of 4 where points[0] is not), and its tile ranges.
bool HistoPyramidGL::Internals::Store(ScalarType type, const void* data, const int points[3],
  int rowValues, const GLParallelFor& run, std::string& error)
{
  const GLApi& gl = *this->GL;
  const GLApi::Functions& f = gl.F();
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  const PyramidLayout layout(cells);
  const int width = PackedVolumeWidth(points[0]);
  const VolumeFormat format = VolumeFormatOf(type);
  ScopedGLState saved(gl, 1);
  gl.TakeErrors();
  const bool sameSize = this->Layout == layout && this->Volume;
  if (!sameSize)
  {
    this->ReleaseLevels();
  }
  this->Built = false;
  this->Queued = false; // and a build queued before is stale
  this->Total = 0;
  this->Volume = Name(gl, NameKind::Texture);
  BindTextureUnit(gl, 0, GL_TEXTURE_3D, this->Volume.Get());
  SetNearest(gl, GL_TEXTURE_3D);
  f.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  f.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  f.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
  f.TexImage3D(GL_TEXTURE_3D, 0, static_cast<GLint>(format.InternalFormat), width, points[1],
    points[2], 0, format.Format, format.Type, data);
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "cannot upload the " + std::to_string(points[0]) + "x" + std::to_string(points[1]) +
      "x" + std::to_string(points[2]) + " volume as a 3D texture: " + errors;
    this->ReleaseAll();
    return false;
  }

  // The value range under each tile of level 1, which lets the level-1 pass
  // draw only the tiles an isovalue can cross.
  this->Tiles.Compute(type, data, points, rowValues, layout, run);
  this->Type = type;
  this->Layout = layout;
  this->Parallel = run;
  std::copy(points, points + 3, this->Points);
  std::fill(this->OwnedFirst, this->OwnedFirst + 3, 0);
  std::copy(cells, cells + 3, this->OwnedEnd);
  return true;
}

void HistoPyramidGL::EmptyTiles()
{
  Internals& impl = *this->Impl;
  if (impl.Volume)
  {
    impl.Tiles.Reset(impl.Type, impl.Layout);
  }
  impl.Built = false;
  impl.Queued = false; // and a build queued before is stale
  impl.Total = 0;
}

bool HistoPyramidGL::UploadRegion(const void* values, const int first[3], const int last[3],
  const PointsArrived& arrived, std::string& error)
{
  Internals& impl = *this->Impl;
  if (!impl.Volume || !values)
  {
    error = "a region needs a volume uploaded first";
    return false;
  }
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = std::max(0, first[a]);
    hi[a] = std::min(impl.Points[a] - 1, last[a]);
    if (lo[a] > hi[a])
    {
      error = "the region is outside the volume";
      return false;
    }
  }
  // The texels of the region's rows: each holds points 4 t .. 4 t + 3 of its row, the row's
  // last point repeated past its end (PackVolumeRows()); doubles become floats as in
  // UploadVolume().
  const VolumeFormat format = VolumeFormatOf(impl.Type);
  const int t0 = lo[0] / 4, t1 = hi[0] / 4;
  const int texels[3] = { t1 - t0 + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1 };
  const int bytes = format.BytesPerValue;
  const int size = ScalarTypeSize(impl.Type);
  std::vector<unsigned char> staging;
  try
  {
    staging.resize(static_cast<std::size_t>(4 * texels[0]) * texels[1] * texels[2] *
      static_cast<std::size_t>(bytes));
  }
  catch (const std::bad_alloc&)
  {
    error = "memory ran out while copying a region for the GPU upload";
    return false;
  }
  const unsigned char* in = static_cast<const unsigned char*>(values);
  unsigned char* out = staging.data();
  for (int z = lo[2]; z <= hi[2]; ++z)
  {
    for (int y = lo[1]; y <= hi[1]; ++y)
    {
      const std::size_t row = (static_cast<std::size_t>(z) * impl.Points[1] + y) * impl.Points[0];
      for (int x = 4 * t0; x < 4 * (t1 + 1); ++x, out += bytes)
      {
        const unsigned char* from = in + (row + std::min(x, impl.Points[0] - 1)) * size;
        if (impl.Type == ScalarType::Float64)
        {
          double d;
          std::memcpy(&d, from, sizeof d);
          const float value = static_cast<float>(d);
          std::memcpy(out, &value, sizeof value);
        }
        else
        {
          std::copy(from, from + bytes, out);
        }
      }
    }
  }
  const GLApi& gl = *impl.GL;
  const int offset[3] = { t0, lo[1], lo[2] };
  if (!UploadBox(gl, impl.Volume.Get(), format, offset, texels, staging.data(), error))
  {
    error = "cannot upload a region of the volume: " + error;
    return false;
  }
  impl.Tiles.ComputeRegion(impl.Type, values, impl.Points, lo, hi, arrived);
  impl.Built = false;
  impl.Queued = false; // and a build queued before is stale
  impl.Total = 0;
  return true;
}

void HistoPyramidGL::SetOwnedCells(const int first[3], const int end[3])
{
  Internals& impl = *this->Impl;
  for (int a = 0; a < 3; ++a)
  {
    impl.OwnedFirst[a] = std::max(0, std::min(first[a], impl.Points[a] - 1));
    impl.OwnedEnd[a] = std::max(impl.OwnedFirst[a], std::min(end[a], impl.Points[a] - 1));
  }
  impl.Built = false;
  impl.Queued = false; // and a build queued before is stale
  impl.Total = 0;
}

void HistoPyramidGL::ShareProgramsWith(const HistoPyramidGL& other)
{
  if (other.Impl->GL == this->Impl->GL)
  {
    this->Impl->Programs = other.Impl->Programs;
  }
}

//------------------------------------------------------------------------------
// Makes `texture` (a 2D texture) the only colour target, with the viewport over it.
bool HistoPyramidGL::Internals::Target(GLuint texture, int width, int height, std::string& error)
{
  const GLApi::Functions& f = this->GL->F();
  f.BindFramebuffer(GL_FRAMEBUFFER, this->FBO.Get());
  f.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  const GLenum buffer = GL_COLOR_ATTACHMENT0;
  f.DrawBuffers(1, &buffer);
  f.ReadBuffer(GL_COLOR_ATTACHMENT0);
  const std::string problem = FramebufferProblem(*this->GL);
  if (!problem.empty())
  {
    error = "an integer render target of the HistoPyramid is incomplete (" + problem + ")";
    return false;
  }
  f.Viewport(0, 0, width, height);
  return true;
}

// A pass program: the full-screen triangle (or the level-1 rectangles) with
// fragment shader `fragment`, the value type's defines and `defines`.
Program* HistoPyramidGL::Internals::Pass(
  const char* vertex, const char* fragment, const std::string& defines, std::string& error)
{
  const Hooks hooks = this->CommonHooks();
  const std::string vs = std::strstr(vertex, "//MEDISO::HistoPyramidCommon") ? Compose(vertex, hooks) : vertex;
  return this->Programs->Get(
    *this->GL, this->Declarations() + defines, vs, Compose(fragment, hooks), error);
}

void HistoPyramidGL::Internals::DrawFullScreen()
{
  const GLApi::Functions& f = this->GL->F();
  if (!this->EmptyVertexArray)
  {
    this->EmptyVertexArray = Name(*this->GL, NameKind::VertexArray);
  }
  f.BindVertexArray(this->EmptyVertexArray.Get());
  f.DrawArrays(GL_TRIANGLES, 0, 3);
}

//------------------------------------------------------------------------------
bool HistoPyramidGL::Build(const std::vector<double>& isovalues, std::string& error)
{
  return this->BuildPasses(isovalues, error) && this->FinishBuild(error);
}

bool HistoPyramidGL::BuildPasses(const std::vector<double>& isovalues, std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  impl.Built = false;
  impl.Queued = false;
  impl.Total = 0;
  if (!impl.Volume)
  {
    error = "Build needs a volume uploaded first";
    return false;
  }
  if (isovalues.empty() || isovalues.size() > static_cast<std::size_t>(MaximumIsovalues))
  {
    error = "Build takes 1 to " + std::to_string(MaximumIsovalues) + " isovalues, not " +
      std::to_string(isovalues.size());
    return false;
  }
  const IsoThresholds thresholds = MakeIsoThresholds(impl.Type, isovalues);
  const PyramidLayout& layout = impl.Layout;
  const int numLevels = layout.GetNumberOfLevels();

  ScopedGLState saved(gl, 2);
  gl.TakeErrors();
  SetCountingPassState(gl);
  f.PixelStorei(GL_PACK_ALIGNMENT, 4);

  // 1. The level atlases, allocated once per volume size.
  if (impl.Levels.empty())
  {
    impl.Levels.emplace_back(); // level 0 is never stored
    for (int l = 1; l < numLevels; ++l)
    {
      const auto atlas = layout.AtlasSize(l);
      const int bytes = layout.BytesPerNode(l);
      const GLenum internalFormat = bytes == 1 ? GL_RGBA8UI : (bytes == 2 ? GL_RGBA16UI : GL_RGBA32UI);
      const GLenum type = bytes == 1 ? GL_UNSIGNED_BYTE : (bytes == 2 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT);
      impl.Levels.emplace_back(gl, NameKind::Texture);
      BindTextureUnit(gl, 1, GL_TEXTURE_2D, impl.Levels.back().Get());
      SetNearest(gl, GL_TEXTURE_2D);
      f.TexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internalFormat), atlas[0], atlas[1], 0,
        GL_RGBA_INTEGER, type, nullptr);
    }
    const std::string errors = gl.TakeErrors();
    if (!errors.empty())
    {
      error = "cannot allocate the pyramid's levels: " + errors;
      impl.ReleaseLevels();
      return false;
    }
  }
  if (!impl.FBO)
  {
    impl.FBO = Name(gl, NameKind::Framebuffer);
  }

  // 2. The programs. One isovalue: level 1 holds each node's child mask,
  //    whose bits the reduction to level 2 counts (with a level 2 to count
  //    them: with at most 2 cells per axis level 1 is the top, whose node
  //    must be the total).
  const bool childMasks = thresholds.Count == 1 && numLevels >= 3;
  Program* first = impl.Pass(shaders::HistoPyramidFirstLevel_vs, shaders::HistoPyramidFirstLevel_fs,
    childMasks ? "#define MEDISO_CHILD_MASKS 1\n" : "", error);
  Program* reduce =
    first ? impl.Pass(shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidReduce_fs, "", error) : nullptr;
  Program* reduceMasks = reduce && childMasks
    ? impl.Pass(shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidReduce_fs,
        "#define MEDISO_LOWER_CHILD_MASKS 1\n", error)
    : reduce;
  if (!first || !reduce || !reduceMasks)
  {
    error = "the HistoPyramid shaders do not build: " + error;
    return false;
  }

  // 3. Level 1 from the volume: cleared to 0, then the active tiles' rectangles.
  std::uint64_t tilesDrawn = 0;
  const std::vector<std::uint16_t> rectangles =
    impl.Tiles.ActiveRectangles(thresholds, impl.Parallel, tilesDrawn);
  {
    const auto atlas = layout.AtlasSize(1);
    if (!impl.Target(impl.Levels[1].Get(), atlas[0], atlas[1], error))
    {
      return false;
    }
    const GLuint zero[4] = { 0, 0, 0, 0 };
    f.ClearBufferuiv(GL_COLOR, 0, zero);
    if (!rectangles.empty())
    {
      first->Use();
      BindTextureUnit(gl, 0, GL_TEXTURE_3D, impl.Volume.Get());
      impl.SetCommonUniforms(*first, thresholds, 0, 1);
      const auto factor = layout.Factor(1);
      const auto shifts = impl.Shifts(1);
      first->Set3i("factor", factor.data());
      first->Set3i("levelSize", layout.Size(1).data());
      first->Set3i("shifts", shifts.data());
      first->Set2f("atlasSize", static_cast<float>(atlas[0]), static_cast<float>(atlas[1]));
      if (!impl.TileVertexArray)
      {
        impl.TileVertexArray = Name(gl, NameKind::VertexArray);
        impl.TileBuffer = Name(gl, NameKind::Buffer);
        f.BindVertexArray(impl.TileVertexArray.Get());
        f.BindBuffer(GL_ARRAY_BUFFER, impl.TileBuffer.Get());
        f.EnableVertexAttribArray(0);
        f.VertexAttribPointer(0, 2, GL_UNSIGNED_SHORT, GL_FALSE, 0, nullptr);
      }
      f.BindVertexArray(impl.TileVertexArray.Get());
      f.BindBuffer(GL_ARRAY_BUFFER, impl.TileBuffer.Get());
      f.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(rectangles.size() * sizeof(std::uint16_t)),
        rectangles.data(), GL_STREAM_DRAW);
      f.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(rectangles.size() / 2));
    }
  }

  // 4. Reductions: level l from level l - 1 (level 2 from child masks by its own variant).
  for (int l = 2; l < numLevels; ++l)
  {
    Program* program = l == 2 ? reduceMasks : reduce;
    const auto atlas = layout.AtlasSize(l);
    if (!impl.Target(impl.Levels[l].Get(), atlas[0], atlas[1], error))
    {
      return false;
    }
    program->Use();
    BindTextureUnit(gl, 1, GL_TEXTURE_2D, impl.Levels[l - 1].Get());
    program->Set("lowerLevel", 1);
    const auto lowerShifts = impl.Shifts(l - 1);
    const auto shifts = impl.Shifts(l);
    program->Set3i("lowerShifts", lowerShifts.data());
    program->Set3i("shifts", shifts.data());
    program->Set3i("factor", layout.Factor(l).data());
    program->Set3i("levelSize", layout.Size(l).data());
    impl.DrawFullScreen();
  }

  f.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "building the HistoPyramid failed: " + errors;
    return false;
  }
  impl.Current = thresholds;
  impl.ChildMasks = childMasks;
  impl.TilesDrawn = tilesDrawn;
  impl.Queued = true;
  return true;
}

bool HistoPyramidGL::FinishBuild(std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  if (!impl.Queued)
  {
    error = "FinishBuild needs BuildPasses() first";
    return false;
  }
  impl.Queued = false;
  // 5. Read back the top node only (which waits for the passes).
  ScopedGLState saved(gl, 1);
  gl.TakeErrors();
  f.PixelStorei(GL_PACK_ALIGNMENT, 4);
  GLuint top[4] = { 0, 0, 0, 0 };
  if (!impl.Target(impl.Levels.back().Get(), 1, 1, error))
  {
    return false;
  }
  f.ReadPixels(0, 0, 1, 1, GL_RGBA_INTEGER, GL_UNSIGNED_INT, top);
  f.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "building the HistoPyramid failed: " + errors;
    return false;
  }
  impl.Total = top[0];
  impl.Built = true;
  if (impl.Pool)
  {
    // Each slot's count: its node of level SlotShift (a few texels read back).
    std::vector<std::uint32_t> counts;
    int size[3];
    if (!this->ReadLevel(impl.SlotShift, counts, size, false, error))
    {
      impl.Built = false;
      return false;
    }
    const int* n = impl.SlotsPerAxis;
    impl.SlotTotals.assign(static_cast<std::size_t>(impl.SlotCount()), 0u);
    for (int z = 0; z < n[2]; ++z)
      for (int y = 0; y < n[1]; ++y)
        for (int x = 0; x < n[0]; ++x)
        {
          impl.SlotTotals[static_cast<std::size_t>(x + n[0] * (y + n[1] * z))] =
            counts[(static_cast<std::size_t>(z) * size[1] + y) * size[0] + x];
        }
    impl.SlotOrderCount = 0;
  }
  return true;
}

bool HistoPyramidGL::AdoptIsovalues(const std::vector<double>& isovalues)
{
  Internals& impl = *this->Impl;
  if (!impl.Built || isovalues.empty() ||
    isovalues.size() > static_cast<std::size_t>(MaximumIsovalues))
  {
    return false;
  }
  const IsoThresholds thresholds = MakeIsoThresholds(impl.Type, isovalues);
  const bool childMasks = thresholds.Count == 1 && impl.Layout.GetNumberOfLevels() >= 3;
  if (childMasks != impl.ChildMasks || (thresholds.Count == 0) != (impl.Current.Count == 0))
  {
    return false;
  }
  impl.Current = thresholds;
  return true;
}

//------------------------------------------------------------------------------
bool HistoPyramidGL::AllocatePool(ScalarType type, int slotPoints, const int slots[3],
  const int drawnCells[3], const GLParallelFor& parallel, std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  const int shift = Log2(slotPoints);
  if (slotPoints < 16 || (1 << shift) != slotPoints || slots[0] < 1 || slots[1] < 1 ||
    slots[2] < 1 || static_cast<long long>(slots[0]) * slots[1] * slots[2] > MaximumSlots)
  {
    error = "a brick pool takes slots of 16 or more points a side, a power of two, and 1 to " +
      std::to_string(MaximumSlots) + " slots";
    return false;
  }
  const int points[3] = { slots[0] * slotPoints, slots[1] * slotPoints, slots[2] * slotPoints };
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  const PyramidLayout layout(cells);
  const int width = PackedVolumeWidth(points[0]);
  std::string limit;
  if (std::max({ width, points[1], points[2] }) > gl.GetMax3DTextureSize())
  {
    limit = "GL_MAX_3D_TEXTURE_SIZE";
  }
  for (int l = 1; l < layout.GetNumberOfLevels(); ++l)
  {
    const auto atlas = layout.AtlasSize(l);
    limit = std::max(atlas[0], atlas[1]) > gl.GetMaxTextureSize() ? "GL_MAX_TEXTURE_SIZE" : limit;
  }
  if (!limit.empty())
  {
    error = "a brick pool of " + std::to_string(slots[0]) + "x" + std::to_string(slots[1]) + "x" +
      std::to_string(slots[2]) + " slots exceeds " + limit;
    return false;
  }
  const VolumeFormat format = VolumeFormatOf(type);
  const int count = slots[0] * slots[1] * slots[2];
  ScopedGLState saved(gl, 1);
  gl.TakeErrors();
  impl.ReleaseAll();
  impl.Volume = Name(gl, NameKind::Texture);
  BindTextureUnit(gl, 0, GL_TEXTURE_3D, impl.Volume.Get());
  SetNearest(gl, GL_TEXTURE_3D);
  f.TexImage3D(GL_TEXTURE_3D, 0, static_cast<GLint>(format.InternalFormat), width, points[1],
    points[2], 0, format.Format, format.Type, nullptr);
  // The table: every slot empty (owns no cell).
  impl.SlotRows.assign(static_cast<std::size_t>(count), std::array<GLuint, 12>{});
  impl.SlotTable = Name(gl, NameKind::Texture);
  BindTextureUnit(gl, 0, GL_TEXTURE_2D, impl.SlotTable.Get());
  SetNearest(gl, GL_TEXTURE_2D);
  f.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  f.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  f.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32UI, 3, count, 0, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
    impl.SlotRows.data());
  impl.SlotOrder = Name(gl, NameKind::Texture);
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "cannot allocate a brick pool of " + std::to_string(points[0]) + "x" +
      std::to_string(points[1]) + "x" + std::to_string(points[2]) + " points: " + errors;
    impl.ReleaseAll();
    return false;
  }
  impl.Pool = true;
  impl.SlotShift = shift;
  std::copy(slots, slots + 3, impl.SlotsPerAxis);
  std::copy(drawnCells, drawnCells + 3, impl.DrawnCells);
  impl.SlotTiles.assign(static_cast<std::size_t>(count), VolumeTiles());
  impl.SlotTotals.assign(static_cast<std::size_t>(count), 0u);
  impl.Type = type;
  impl.Layout = layout;
  impl.Parallel = SerialIfEmpty(parallel);
  impl.Tiles.Reset(type, layout);
  std::copy(points, points + 3, impl.Points);
  std::fill(impl.OwnedFirst, impl.OwnedFirst + 3, 0);
  std::fill(impl.OwnedEnd, impl.OwnedEnd + 3, 0);
  return true;
}

bool HistoPyramidGL::Internals::SlotFits(
  int slot, const void* values, const int points[3], std::string& error) const
{
  const int side = 1 << this->SlotShift;
  if (!this->Pool || slot < 0 || slot >= this->SlotCount() || !values ||
    std::min({ points[0], points[1], points[2] }) < 2 ||
    std::max({ points[0], points[1], points[2] }) > side)
  {
    error = "a brick of " + std::to_string(points[0]) + "x" + std::to_string(points[1]) + "x" +
      std::to_string(points[2]) + " points does not fit slot " + std::to_string(slot) +
      " of the brick pool";
    return false;
  }
  return true;
}

bool HistoPyramidGL::UploadSlot(
  int slot, const void* values, const int points[3], const int placement[3], std::string& error)
{
  Internals& impl = *this->Impl;
  if (!impl.SlotFits(slot, values, points, error))
  {
    return false;
  }
  const std::int64_t numPoints = static_cast<std::int64_t>(points[0]) * points[1] * points[2];
  const VolumeFormat format = VolumeFormatOf(impl.Type);
  std::vector<float> converted;
  std::vector<unsigned char> packed;
  const void* data = values;
  try
  {
    if (impl.Type == ScalarType::Float64)
    {
      converted.resize(static_cast<std::size_t>(numPoints));
      const double* d = static_cast<const double*>(values);
      for (std::int64_t i = 0; i < numPoints; ++i)
      {
        converted[static_cast<std::size_t>(i)] = static_cast<float>(d[i]);
      }
      data = converted.data();
    }
    if (points[0] % 4 != 0)
    {
      packed = PackVolumeRows(data, points, format.BytesPerValue, impl.Parallel);
    }
  }
  catch (const std::bad_alloc&)
  {
    error = "memory ran out while copying a brick for the GPU upload";
    return false;
  }
  return impl.StoreSlot(slot, packed.empty() ? data : packed.data(), points,
    packed.empty() ? points[0] : 4 * PackedVolumeWidth(points[0]), placement, error);
}

bool HistoPyramidGL::UploadPackedSlot(int slot, const void* packedRows, const int points[3],
  const int placement[3], std::string& error)
{
  Internals& impl = *this->Impl;
  if (!impl.SlotFits(slot, packedRows, points, error))
  {
    return false;
  }
  if (impl.Type == ScalarType::Float64)
  {
    error = "packed rows hold the texture's values, and a double volume's texture holds floats";
    return false;
  }
  return impl.StoreSlot(
    slot, packedRows, points, 4 * PackedVolumeWidth(points[0]), placement, error);
}

// A slot's texels from `data`, the texture's values with rows of `rowValues`, its tile
// ranges and its row of the table (owning no cell yet).
bool HistoPyramidGL::Internals::StoreSlot(int slot, const void* data, const int points[3],
  int rowValues, const int placement[3], std::string& error)
{
  const int side = 1 << this->SlotShift;
  const VolumeFormat format = VolumeFormatOf(this->Type);
  const int* n = this->SlotsPerAxis;
  const int offset[3] = { (slot % n[0]) * side / 4, ((slot / n[0]) % n[1]) * side,
    (slot / (n[0] * n[1])) * side };
  const int texels[3] = { PackedVolumeWidth(points[0]), points[1], points[2] };
  if (!UploadBox(*this->GL, this->Volume.Get(), format, offset, texels, data, error))
  {
    error = "cannot upload a brick into the brick pool: " + error;
    return false;
  }
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  this->SlotTiles[static_cast<std::size_t>(slot)].Compute(
    this->Type == ScalarType::Float64 ? ScalarType::Float32 : this->Type, data, points,
    rowValues, PyramidLayout(cells), this->Parallel);
  std::array<GLuint, 12>& row = this->SlotRows[static_cast<std::size_t>(slot)];
  for (int a = 0; a < 3; ++a)
  {
    row[a] = row[4 + a] = 0; // owns nothing until SetSlotCells()
    row[8 + a] = static_cast<GLuint>(cells[a]);
    row[4 * a + 3] = static_cast<GLuint>(placement[a]);
  }
  this->UpdateSlot(slot);
  return true;
}

void HistoPyramidGL::SetSlotCells(int slot, const int first[3], const int end[3])
{
  Internals& impl = *this->Impl;
  if (!impl.Pool || slot < 0 || slot >= impl.SlotCount())
  {
    return;
  }
  std::array<GLuint, 12>& row = impl.SlotRows[static_cast<std::size_t>(slot)];
  bool empty = false;
  for (int a = 0; a < 3; ++a)
  {
    const int last = static_cast<int>(row[8 + a]);
    const int lo = std::max(0, std::min(first[a], last));
    const int hi = std::max(lo, std::min(end[a], last));
    empty = empty || lo == hi;
    row[a] = static_cast<GLuint>(lo);
    row[4 + a] = static_cast<GLuint>(hi);
  }
  if (empty)
  {
    for (int a = 0; a < 3; ++a)
    {
      row[a] = row[4 + a] = 0;
    }
  }
  impl.UpdateSlot(slot);
}

void HistoPyramidGL::Internals::UpdateSlot(int slot)
{
  const GLApi& gl = *this->GL;
  const GLApi::Functions& f = gl.F();
  const std::array<GLuint, 12>& row = this->SlotRows[static_cast<std::size_t>(slot)];
  {
    ScopedGLState saved(gl, 1);
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->SlotTable.Get());
    f.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    f.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    f.TexSubImage2D(GL_TEXTURE_2D, 0, 0, slot, 3, 1, GL_RGBA_INTEGER, GL_UNSIGNED_INT, row.data());
  }
  // Its tiles: the brick's where it owns cells, else none drawn.
  const int side = 1 << this->SlotShift;
  const int* n = this->SlotsPerAxis;
  const int s[3] = { slot % n[0], (slot / n[0]) % n[1], slot / (n[0] * n[1]) };
  const int cellsPerTile[3] = { 4 * PyramidLayout::TileTexels, 4 * PyramidLayout::TileTexels, 2 };
  int origin[3], count[3];
  for (int a = 0; a < 3; ++a)
  {
    origin[a] = s[a] * side / cellsPerTile[a];
    count[a] = side / cellsPerTile[a];
  }
  const bool owns = row[4] > row[0];
  this->Tiles.Place(
    owns ? &this->SlotTiles[static_cast<std::size_t>(slot)] : nullptr, origin, count);
  this->Built = false;
  this->Queued = false; // and a build queued before is stale
  this->Total = 0;
}

void HistoPyramidGL::SetSlotOrder(const std::vector<int>& slots)
{
  Internals& impl = *this->Impl;
  if (!impl.Pool || !impl.Built)
  {
    return;
  }
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  // Entries (first primitive, slot x, y, z) of the slots with primitives, in
  // the order given, then any such slot not given (every primitive must
  // find its slot).
  std::vector<GLuint> entries;
  std::vector<char> listed(impl.SlotTotals.size(), 0);
  GLuint first = 0;
  const int* n = impl.SlotsPerAxis;
  auto add = [&](int slot)
  {
    if (slot < 0 || slot >= impl.SlotCount() || listed[static_cast<std::size_t>(slot)] ||
      impl.SlotTotals[static_cast<std::size_t>(slot)] == 0)
    {
      return;
    }
    listed[static_cast<std::size_t>(slot)] = 1;
    entries.insert(entries.end(),
      { first, static_cast<GLuint>(slot % n[0]), static_cast<GLuint>((slot / n[0]) % n[1]),
        static_cast<GLuint>(slot / (n[0] * n[1])) });
    first += impl.SlotTotals[static_cast<std::size_t>(slot)];
  };
  for (const int slot : slots)
  {
    add(slot);
  }
  for (int slot = 0; slot < impl.SlotCount(); ++slot)
  {
    add(slot);
  }
  impl.SlotOrderCount = static_cast<int>(entries.size() / 4);
  const int rows = std::max(1, (impl.SlotOrderCount + 63) / 64);
  entries.resize(static_cast<std::size_t>(4 * 64 * rows), 0u);
  ScopedGLState saved(gl, 1);
  BindTextureUnit(gl, 0, GL_TEXTURE_2D, impl.SlotOrder.Get());
  SetNearest(gl, GL_TEXTURE_2D);
  f.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  f.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  f.TexImage2D(
    GL_TEXTURE_2D, 0, GL_RGBA32UI, 64, rows, 0, GL_RGBA_INTEGER, GL_UNSIGNED_INT, entries.data());
}

bool HistoPyramidGL::IsPool() const
{
  return this->Impl->Pool;
}

int HistoPyramidGL::GetNumberOfSlots() const
{
  return this->Impl->Pool ? this->Impl->SlotCount() : 0;
}

const std::vector<std::uint32_t>& HistoPyramidGL::GetSlotTotals() const
{
  return this->Impl->SlotTotals;
}

std::array<int, 3> HistoPyramidGL::GetDrawnCells() const
{
  const Internals& impl = *this->Impl;
  if (impl.Pool)
  {
    return { { impl.DrawnCells[0], impl.DrawnCells[1], impl.DrawnCells[2] } };
  }
  return impl.Layout.GetCells();
}

//------------------------------------------------------------------------------
bool HistoPyramidGL::ReadLevel(
  int level, std::vector<std::uint32_t>& counts, int size[3], bool asStored, std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  const PyramidLayout& layout = impl.Layout;
  if (!impl.Built || level < 0 || level >= layout.GetNumberOfLevels())
  {
    error = "no such level";
    return false;
  }
  const auto& s = layout.Size(level);
  std::copy(s.begin(), s.end(), size);
  counts.assign(static_cast<std::size_t>(s[0]) * s[1] * s[2], 0u);

  ScopedGLState saved(gl, 2);
  gl.TakeErrors();
  SetCountingPassState(gl);
  f.PixelStorei(GL_PACK_ALIGNMENT, 4);

  if (level == 0)
  {
    // The base level is not stored: draw it, one count per texel, into a
    // temporary atlas (slices side by side as in the stored levels).
    int columns = 1;
    while (columns < s[2] && static_cast<long long>(s[0]) * columns < static_cast<long long>(s[1]) * (s[2] / columns))
    {
      columns *= 2;
    }
    const int width = s[0] * columns, height = s[1] * (s[2] / columns);
    if (std::max(width, height) > gl.GetMaxTextureSize())
    {
      error = "the base level is too large to read back";
      return false;
    }
    Program* base = impl.Pass(shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidBase_fs, "", error);
    if (!base)
    {
      return false;
    }
    Name texture(gl, NameKind::Texture);
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, texture.Get());
    SetNearest(gl, GL_TEXTURE_2D);
    f.TexImage2D(GL_TEXTURE_2D, 0, GL_R32UI, width, height, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    if (!impl.Target(texture.Get(), width, height, error))
    {
      return false;
    }
    base->Use();
    BindTextureUnit(gl, 0, GL_TEXTURE_3D, impl.Volume.Get());
    impl.SetCommonUniforms(*base, impl.Current, 0, 1);
    const int shifts[3] = { Log2(s[0]), Log2(s[1]), Log2(columns) };
    base->Set3i("shifts", shifts);
    impl.DrawFullScreen();
    std::vector<GLuint> texels(4 * static_cast<std::size_t>(width) * height);
    f.ReadPixels(0, 0, width, height, GL_RGBA_INTEGER, GL_UNSIGNED_INT, texels.data());
    for (int z = 0; z < s[2]; ++z)
      for (int y = 0; y < s[1]; ++y)
        for (int x = 0; x < s[0]; ++x)
        {
          const int ax = x + (z % columns) * s[0], ay = y + (z / columns) * s[1];
          counts[(static_cast<std::size_t>(z) * s[1] + y) * s[0] + x] =
            texels[4 * (static_cast<std::size_t>(ay) * width + ax)];
        }
  }
  else
  {
    const auto atlas = layout.AtlasSize(level);
    if (!impl.Target(impl.Levels[level].Get(), atlas[0], atlas[1], error))
    {
      return false;
    }
    std::vector<GLuint> texels(4 * static_cast<std::size_t>(atlas[0]) * atlas[1]);
    f.ReadPixels(0, 0, atlas[0], atlas[1], GL_RGBA_INTEGER, GL_UNSIGNED_INT, texels.data());
    // Level 1 holding child masks comes back as their counts of set bits.
    const bool countBits = level == 1 && impl.ChildMasks && !asStored;
    for (int z = 0; z < s[2]; ++z)
      for (int y = 0; y < s[1]; ++y)
        for (int x = 0; x < s[0]; ++x)
        {
          const auto a = layout.AtlasTexel(level, x / 2, y / 2, z);
          const GLuint node =
            texels[4 * (static_cast<std::size_t>(a[1]) * atlas[0] + a[0]) + (x & 1) + 2 * (y & 1)];
          counts[(static_cast<std::size_t>(z) * s[1] + y) * s[0] + x] = countBits
            ? static_cast<std::uint32_t>(std::bitset<8>(node).count())
            : static_cast<std::uint32_t>(node);
        }
  }
  f.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "reading level " + std::to_string(level) + " back failed: " + errors;
    return false;
  }
  return true;
}

} // namespace mediso
