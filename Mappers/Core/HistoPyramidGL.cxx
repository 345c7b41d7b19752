// SPDX-License-Identifier: BSD-3-Clause
#include "HistoPyramidGL.h"

#include "GLObjects.h"
#include "HistoPyramidGLInternals.h"
#include "MedisoShaders.h"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <cstring>
#include <limits>

namespace mediso
{
namespace
{
using namespace glcore;

// Texels per row of the stored volume: 4 points to a texel along x.
int PackedVolumeWidth(int pointsX)
{
  return (pointsX + 3) / 4;
}

// The volume as its texture stores it: texel (i, j, k) holds points
// (4 i + c, j, k) in component c, and where a row's points run out, its last
// texel repeats the row's last point (so a read past the end of a row gives
// the value a clamp to the volume would). Rows are copied as bytes, so the
// values keep their type. Readers: pointQuad() and pointValue() in
// HistoPyramidCommon.glsl.
std::vector<unsigned char> PackVolumeRows(
  const void* data, const int points[3], int bytesPerValue, const GLParallelFor& parallel)
{
  const std::size_t inRow = static_cast<std::size_t>(points[0]) * bytesPerValue;
  const std::size_t outRow = static_cast<std::size_t>(4 * PackedVolumeWidth(points[0])) * bytesPerValue;
  const std::int64_t rows = static_cast<std::int64_t>(points[1]) * points[2];
  std::vector<unsigned char> packed(outRow * static_cast<std::size_t>(rows));
  const unsigned char* in = static_cast<const unsigned char*>(data);
  parallel(0, rows,
    [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t r = begin; r < end; ++r)
      {
        const unsigned char* from = in + inRow * r;
        unsigned char* to = packed.data() + outRow * r;
        std::copy(from, from + inRow, to);
        for (std::size_t pad = inRow; pad < outRow; pad += bytesPerValue)
        {
          std::copy(from + inRow - bytesPerValue, from + inRow, to + pad);
        }
      }
    });
  return packed;
}

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

// The range of point values each level-1 tile's real cells read: out[2 t]
// the least and out[2 t + 1] the greatest (t = x + tiles.x (y + tiles.y z)),
// as R (int32, uint32 or float: every value of T is exact in it). An empty
// tile (padding cells only, or only NaN values) gets least > greatest, which
// no threshold lies between. NaN values are left out: a cell with a NaN
// corner counts nothing anyway.
template <typename T, typename R>
void ComputeTileRanges(const T* data, const int points[3], const PyramidLayout& layout,
  const GLParallelFor& parallel, std::vector<R>& out)
{
  const auto tiles = layout.TileCounts();
  const auto factor = layout.Factor(1);
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  // Cells per tile along x and y (a packed texel holds 2 nodes per axis).
  const int span[2] = { 2 * PyramidLayout::TileTexels * factor[0],
    2 * PyramidLayout::TileTexels * factor[1] };
  const std::size_t perSlice = static_cast<std::size_t>(tiles[0]) * tiles[1];
  const R none = std::numeric_limits<R>::has_infinity ? std::numeric_limits<R>::infinity()
                                                      : std::numeric_limits<R>::max();
  const R noneHigh = std::numeric_limits<R>::has_infinity ? -std::numeric_limits<R>::infinity()
                                                          : std::numeric_limits<R>::lowest();
  out.assign(2 * perSlice * tiles[2], R());
  parallel(0, tiles[2],
    [&](std::int64_t sliceBegin, std::int64_t sliceEnd)
    {
      std::vector<R> rowLow(tiles[0]), rowHigh(tiles[0]);
      for (std::int64_t slice = sliceBegin; slice < sliceEnd; ++slice)
      {
        R* ranges = out.data() + 2 * perSlice * slice;
        for (std::size_t t = 0; t < perSlice; ++t)
        {
          ranges[2 * t] = none;
          ranges[2 * t + 1] = noneHigh;
        }
        // The slice's cells along z, and so its points [z0, z1].
        const int z0 = static_cast<int>(slice) * factor[2];
        if (z0 >= cells[2])
        {
          continue;
        }
        const int z1 = std::min(z0 + factor[2], cells[2]);
        for (int z = z0; z <= z1; ++z)
        {
          for (int y = 0; y < points[1]; ++y)
          {
            const T* row = data + (static_cast<std::size_t>(z) * points[1] + y) * points[0];
            // Each tile's points of this row: x in [tx span, min((tx + 1) span, cells)].
            for (int tx = 0; tx < tiles[0]; ++tx)
            {
              R low = none, high = noneHigh;
              const int x0 = tx * span[0];
              const int x1 = std::min(x0 + span[0], cells[0]);
              for (int x = x0; x <= x1 && x0 < cells[0]; ++x)
              {
                const R v = static_cast<R>(row[x]);
                low = v < low ? v : low; // NaN compares false: left out
                high = v > high ? v : high;
              }
              rowLow[tx] = low;
              rowHigh[tx] = high;
            }
            // The row belongs to the tiles whose points along y hold y: one,
            // or two where it is the boundary between them.
            const int ty = std::min(y / span[1], tiles[1] - 1);
            for (int t = ty; t >= 0 && t >= ty - 1; --t)
            {
              const int ya = t * span[1];
              if (ya >= cells[1] || y < ya || y > std::min(ya + span[1], cells[1]))
              {
                continue;
              }
              R* tile = ranges + 2 * static_cast<std::size_t>(t) * tiles[0];
              for (int tx = 0; tx < tiles[0]; ++tx)
              {
                tile[2 * tx] = rowLow[tx] < tile[2 * tx] ? rowLow[tx] : tile[2 * tx];
                tile[2 * tx + 1] = rowHigh[tx] > tile[2 * tx + 1] ? rowHigh[tx] : tile[2 * tx + 1];
              }
            }
          }
        }
      }
    });
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

void SerialFor(std::int64_t begin, std::int64_t end,
  const std::function<void(std::int64_t, std::int64_t)>& body)
{
  if (begin < end)
  {
    body(begin, end);
  }
}
} // namespace

//------------------------------------------------------------------------------
std::array<int, 3> HistoPyramidGL::Internals::Shifts(int level) const
{
  const auto packed = this->Layout.Packed(level);
  return { Log2(packed[0]), Log2(packed[1]), Log2(this->Layout.AtlasColumns(level)) };
}

std::string HistoPyramidGL::Internals::Declarations() const
{
  return ValueKindDefines(ValueKindOf(this->Type));
}

glcore::Hooks HistoPyramidGL::Internals::CommonHooks() const
{
  return { { "HistoPyramidCommon", shaders::HistoPyramidCommon } };
}

void HistoPyramidGL::Internals::SetCommonUniforms(
  glcore::Program& program, const IsoThresholds& t, int volumeUnit) const
{
  program.Set("volume", volumeUnit);
  program.Set("numberOfThresholds", t.Count);
  const int cells[3] = { this->Points[0] - 1, this->Points[1] - 1, this->Points[2] - 1 };
  program.Set3i("cellDimensions", cells);
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
  this->Programs.Clear();
  this->IntRanges.clear();
  this->UIntRanges.clear();
  this->FloatRanges.clear();
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
bool HistoPyramidGL::UploadVolume(ScalarType type, const void* values, const int points[3],
  const GLParallelFor& parallel, std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  if (!values || !points)
  {
    error = "no volume given";
    return false;
  }
  if (points[0] < 2 || points[1] < 2 || points[2] < 2)
  {
    error = "the volume must have at least 2 points per axis, not " + std::to_string(points[0]) +
      "x" + std::to_string(points[1]) + "x" + std::to_string(points[2]);
    return false;
  }
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  const PyramidLayout layout(cells);
  const int width = PackedVolumeWidth(points[0]);
  if (std::max({ width, points[1], points[2] }) > gl.GetMax3DTextureSize())
  {
    error = "the " + std::to_string(points[0]) + "x" + std::to_string(points[1]) + "x" +
      std::to_string(points[2]) + " volume (a " + std::to_string(width) + "x" +
      std::to_string(points[1]) + "x" + std::to_string(points[2]) +
      " texture) exceeds GL_MAX_3D_TEXTURE_SIZE " + std::to_string(gl.GetMax3DTextureSize());
    return false;
  }
  for (int l = 1; l < layout.GetNumberOfLevels(); ++l)
  {
    const auto atlas = layout.AtlasSize(l);
    if (std::max(atlas[0], atlas[1]) > gl.GetMaxTextureSize())
    {
      error = "level " + std::to_string(l) + " of the pyramid (a " + std::to_string(atlas[0]) +
        "x" + std::to_string(atlas[1]) + " texture) exceeds GL_MAX_TEXTURE_SIZE " +
        std::to_string(gl.GetMaxTextureSize());
      return false;
    }
  }
  const GLParallelFor& run = parallel ? parallel : GLParallelFor(SerialFor);
  const std::int64_t numPoints = static_cast<std::int64_t>(points[0]) * points[1] * points[2];

  // Double data is converted to float; every other type goes up as it is.
  std::vector<float> converted;
  const void* data = values;
  if (type == ScalarType::Float64)
  {
    converted.resize(static_cast<std::size_t>(numPoints));
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
  const VolumeFormat format = VolumeFormatOf(type);

  ScopedGLState saved(gl, 1);
  gl.TakeErrors();
  const bool sameSize = impl.Layout == layout && impl.Volume;
  if (!sameSize)
  {
    impl.ReleaseLevels();
  }
  impl.Built = false;
  impl.Total = 0;
  impl.Volume = Name(gl, NameKind::Texture);
  BindTextureUnit(gl, 0, GL_TEXTURE_3D, impl.Volume.Get());
  SetNearest(gl, GL_TEXTURE_3D);
  f.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  f.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  f.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
  {
    std::vector<unsigned char> packed;
    if (points[0] % 4 != 0)
    {
      packed = PackVolumeRows(data, points, format.BytesPerValue, run);
    }
    f.TexImage3D(GL_TEXTURE_3D, 0, static_cast<GLint>(format.InternalFormat), width, points[1],
      points[2], 0, format.Format, format.Type, packed.empty() ? data : packed.data());
  }
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "cannot upload the " + std::to_string(points[0]) + "x" + std::to_string(points[1]) +
      "x" + std::to_string(points[2]) + " volume as a 3D texture: " + errors;
    impl.ReleaseAll();
    return false;
  }

  // The value range under each tile of level 1, which lets the level-1 pass
  // draw only the tiles an isovalue can cross.
  impl.IntRanges.clear();
  impl.UIntRanges.clear();
  impl.FloatRanges.clear();
  const ScalarType rangeType = type == ScalarType::Float64 ? ScalarType::Float32 : type;
  VisitScalarType(rangeType,
    [&](auto tag)
    {
      using T = decltype(tag);
      const T* typed = static_cast<const T*>(data);
      switch (ValueKindOf(type))
      {
        case ValueKind::Signed:
          ComputeTileRanges(typed, points, layout, run, impl.IntRanges);
          break;
        case ValueKind::Unsigned:
          ComputeTileRanges(typed, points, layout, run, impl.UIntRanges);
          break;
        case ValueKind::Float:
          ComputeTileRanges(typed, points, layout, run, impl.FloatRanges);
          break;
      }
    });
  impl.Type = type;
  impl.Layout = layout;
  impl.Parallel = run;
  std::copy(points, points + 3, impl.Points);
  return true;
}

//------------------------------------------------------------------------------
// The rectangles of the level-1 pass: per slice and row of tiles, each run of
// tiles whose range holds a threshold, as two triangles in atlas texels.
std::vector<std::uint16_t> HistoPyramidGL::Internals::ActiveTileRectangles(
  const IsoThresholds& thresholds, std::uint64_t& tilesDrawn) const
{
  const auto tiles = this->Layout.TileCounts();
  const auto packed = this->Layout.Packed(1);
  const std::size_t perSlice = static_cast<std::size_t>(tiles[0]) * tiles[1];
  auto active = [&](std::size_t t) -> bool
  {
    switch (thresholds.Kind)
    {
      case ValueKind::Signed:
        return thresholds.Crosses(this->IntRanges[2 * t], this->IntRanges[2 * t + 1]);
      case ValueKind::Unsigned:
        return thresholds.Crosses(this->UIntRanges[2 * t], this->UIntRanges[2 * t + 1]);
      default:
        return thresholds.Crosses(this->FloatRanges[2 * t], this->FloatRanges[2 * t + 1]);
    }
  };
  // Per slice, in parallel; then joined in slice order.
  std::vector<std::vector<std::uint16_t>> slices(static_cast<std::size_t>(tiles[2]));
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(tiles[2]), 0);
  this->Parallel(0, tiles[2],
    [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t z = begin; z < end; ++z)
      {
        std::vector<std::uint16_t>& out = slices[z];
        for (int ty = 0; ty < tiles[1]; ++ty)
        {
          for (int tx = 0; tx < tiles[0];)
          {
            const std::size_t t = perSlice * z + static_cast<std::size_t>(ty) * tiles[0];
            if (!active(t + tx))
            {
              ++tx;
              continue;
            }
            int end = tx + 1;
            while (end < tiles[0] && active(t + end))
            {
              ++end;
            }
            counts[z] += static_cast<std::uint64_t>(end - tx);
            const auto lo = this->Layout.AtlasTexel(1, tx * PyramidLayout::TileTexels,
              ty * PyramidLayout::TileTexels, static_cast<int>(z));
            const int w = std::min(end * PyramidLayout::TileTexels, packed[0]) - tx * PyramidLayout::TileTexels;
            const int h = std::min((ty + 1) * PyramidLayout::TileTexels, packed[1]) -
              ty * PyramidLayout::TileTexels;
            const std::uint16_t x0 = static_cast<std::uint16_t>(lo[0]);
            const std::uint16_t y0 = static_cast<std::uint16_t>(lo[1]);
            const std::uint16_t x1 = static_cast<std::uint16_t>(lo[0] + w);
            const std::uint16_t y1 = static_cast<std::uint16_t>(lo[1] + h);
            out.insert(out.end(), { x0, y0, x1, y0, x0, y1, x0, y1, x1, y0, x1, y1 });
            tx = end;
          }
        }
      }
    });
  std::vector<std::uint16_t> all;
  std::size_t size = 0;
  for (const auto& s : slices)
  {
    size += s.size();
  }
  all.reserve(size);
  tilesDrawn = 0;
  for (std::size_t z = 0; z < slices.size(); ++z)
  {
    all.insert(all.end(), slices[z].begin(), slices[z].end());
    tilesDrawn += counts[z];
  }
  return all;
}

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
glcore::Program* HistoPyramidGL::Internals::Pass(
  const char* vertex, const char* fragment, const std::string& defines, std::string& error)
{
  const Hooks hooks = this->CommonHooks();
  const std::string vs = std::strstr(vertex, "//MEDISO::HistoPyramidCommon") ? Compose(vertex, hooks) : vertex;
  return this->Programs.Get(
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
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  impl.Built = false;
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
  const std::vector<std::uint16_t> rectangles = impl.ActiveTileRectangles(thresholds, tilesDrawn);
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
      impl.SetCommonUniforms(*first, thresholds, 0);
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

  // 5. Read back the top node only.
  GLuint top[4] = { 0, 0, 0, 0 };
  if (!impl.Target(impl.Levels[numLevels - 1].Get(), 1, 1, error))
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
  impl.Current = thresholds;
  impl.ChildMasks = childMasks;
  impl.TilesDrawn = tilesDrawn;
  impl.Built = true;
  return true;
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

  ScopedGLState saved(gl, 1);
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
    impl.SetCommonUniforms(*base, impl.Current, 0);
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
