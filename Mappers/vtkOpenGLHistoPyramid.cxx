// SPDX-License-Identifier: BSD-3-Clause
#include "vtkOpenGLHistoPyramid.h"

#include "vtkMedicalGLUtilities.h"
#include "vtkDataArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLVertexArrayObject.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkType.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkHistoPyramidBase_fs.h"
#include "vtkHistoPyramidCommon.h"
#include "vtkHistoPyramidFirstLevel_fs.h"
#include "vtkHistoPyramidFirstLevel_gs.h"
#include "vtkHistoPyramidFirstLevel_vs.h"
#include "vtkHistoPyramidLayer_gs.h"
#include "vtkHistoPyramidLayer_vs.h"
#include "vtkHistoPyramidPacked.h"
#include "vtkHistoPyramidReduce_fs.h"

#include <algorithm>
#include <array>
#include <bitset>
#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkOpenGLHistoPyramid);

namespace
{
using namespace medical_gl;
// How the base pass compares values: the GLSL value type of the volume.
enum class ValueKind
{
  Signed,   // isampler3D, int
  Unsigned, // usampler3D, uint
  Float     // sampler3D, float
};

// The texture format of a VTK scalar type, and the range of its values. The
// volume is stored 4 points to a texel along x (see PackVolumeRows()), so
// the formats are the RGBA ones of the value type.
struct VolumeFormat
{
  GLenum InternalFormat = 0;
  GLenum Format = 0;
  GLenum DataType = 0;
  int UploadVTKType = 0; // type of the array handed to vtkTextureObject
  int BytesPerValue = 0;
  ValueKind Kind = ValueKind::Float;
  double Min = 0.0; // value range of integer types
  double Max = 0.0;
};

template <typename T>
VolumeFormat IntegerFormat(GLenum internalFormat, GLenum dataType, int uploadType)
{
  VolumeFormat f;
  f.InternalFormat = internalFormat;
  f.Format = GL_RGBA_INTEGER;
  f.DataType = dataType;
  f.UploadVTKType = uploadType;
  f.BytesPerValue = static_cast<int>(sizeof(T));
  f.Kind = std::numeric_limits<T>::is_signed ? ValueKind::Signed : ValueKind::Unsigned;
  f.Min = static_cast<double>(std::numeric_limits<T>::lowest());
  f.Max = static_cast<double>(std::numeric_limits<T>::max());
  return f;
}

bool ChooseFormat(int vtkType, VolumeFormat& f)
{
  switch (vtkType)
  {
    case VTK_CHAR:
      // Plain char is signed or unsigned depending on the platform.
      f = std::numeric_limits<char>::is_signed
        ? IntegerFormat<signed char>(GL_RGBA8I, GL_BYTE, VTK_SIGNED_CHAR)
        : IntegerFormat<unsigned char>(GL_RGBA8UI, GL_UNSIGNED_BYTE, VTK_UNSIGNED_CHAR);
      return true;
    case VTK_SIGNED_CHAR:
      f = IntegerFormat<signed char>(GL_RGBA8I, GL_BYTE, VTK_SIGNED_CHAR);
      return true;
    case VTK_UNSIGNED_CHAR:
      f = IntegerFormat<unsigned char>(GL_RGBA8UI, GL_UNSIGNED_BYTE, VTK_UNSIGNED_CHAR);
      return true;
    case VTK_SHORT:
      f = IntegerFormat<short>(GL_RGBA16I, GL_SHORT, VTK_SHORT);
      return true;
    case VTK_UNSIGNED_SHORT:
      f = IntegerFormat<unsigned short>(GL_RGBA16UI, GL_UNSIGNED_SHORT, VTK_UNSIGNED_SHORT);
      return true;
    case VTK_INT:
      f = IntegerFormat<int>(GL_RGBA32I, GL_INT, VTK_INT);
      return true;
    case VTK_UNSIGNED_INT:
      f = IntegerFormat<unsigned int>(GL_RGBA32UI, GL_UNSIGNED_INT, VTK_UNSIGNED_INT);
      return true;
    case VTK_FLOAT:
    case VTK_DOUBLE: // converted to float on upload
      f.InternalFormat = GL_RGBA32F;
      f.Format = GL_RGBA;
      f.DataType = GL_FLOAT;
      f.UploadVTKType = VTK_FLOAT;
      f.BytesPerValue = 4;
      f.Kind = ValueKind::Float;
      return true;
    default:
      return false;
  }
}

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
// vtkHistoPyramidCommon.glsl. With a multiple of 4 points per row the data
// is already laid out so, and is uploaded as it is (this is not called).
std::vector<unsigned char> PackVolumeRows(const void* data, const int points[3], int bytesPerValue)
{
  const std::size_t inRow = static_cast<std::size_t>(points[0]) * bytesPerValue;
  const std::size_t outRow = static_cast<std::size_t>(4 * PackedVolumeWidth(points[0])) * bytesPerValue;
  const vtkIdType rows = static_cast<vtkIdType>(points[1]) * points[2];
  std::vector<unsigned char> packed(outRow * static_cast<std::size_t>(rows));
  const unsigned char* in = static_cast<const unsigned char*>(data);
  vtkSMPTools::For(0, rows,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType r = begin; r < end; ++r)
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

// The #defines that select the value type in vtkHistoPyramidCommon.glsl.
const char* ValueTypeDefines(ValueKind kind)
{
  switch (kind)
  {
    case ValueKind::Signed:
      return "#define VALUE_SAMPLER isampler3D\n#define VALUE_TYPE int\n#define VALUE_VEC4 ivec4\n";
    case ValueKind::Unsigned:
      return "#define VALUE_SAMPLER usampler3D\n#define VALUE_TYPE uint\n#define VALUE_VEC4 uvec4\n";
    case ValueKind::Float:
    default:
      return "#define VALUE_SAMPLER sampler3D\n#define VALUE_TYPE float\n#define VALUE_VEC4 "
             "vec4\n#define VALUE_IS_FLOAT 1\n";
  }
}

// Thresholds t of the texture's value type with, for every value v of that
// type, (v < t) == (v < iso) and (t <= v) == (iso <= v), so that the base
// pass counts exactly what the CPU counts in double precision. Isovalues that
// can cross no cell of the type's range (and NaN ones) are left out.
struct Thresholds
{
  std::vector<GLint> Ints;
  std::vector<GLuint> UInts;
  std::vector<GLfloat> Floats;
  std::vector<int> Indices; // isovalue index of each threshold
  int Count = 0;
};

Thresholds MakeThresholds(const VolumeFormat& f, const std::vector<double>& isovalues)
{
  Thresholds t;
  for (std::size_t index = 0; index < isovalues.size(); ++index)
  {
    const double iso = isovalues[index];
    if (std::isnan(iso))
    {
      continue;
    }
    if (f.Kind == ValueKind::Float)
    {
      // The smallest float not below iso (+inf above the float range).
      float value;
      if (iso > static_cast<double>(FLT_MAX))
      {
        value = std::numeric_limits<float>::infinity();
      }
      else if (iso < -static_cast<double>(FLT_MAX))
      {
        value = -FLT_MAX;
      }
      else
      {
        value = static_cast<float>(iso);
        if (static_cast<double>(value) < iso)
        {
          value = std::nextafter(value, std::numeric_limits<float>::infinity());
        }
      }
      t.Floats.push_back(value);
    }
    else
    {
      // For integers v: v < iso <=> v < ceil(iso), iso <= v <=> ceil(iso) <= v.
      // A threshold above the maximum, or at or below the minimum, never
      // satisfies min < t <= max.
      const double c = std::ceil(iso);
      if (c > f.Max || c <= f.Min)
      {
        continue;
      }
      if (f.Kind == ValueKind::Signed)
      {
        t.Ints.push_back(static_cast<GLint>(c));
      }
      else
      {
        t.UInts.push_back(static_cast<GLuint>(c));
      }
    }
    t.Indices.push_back(static_cast<int>(index));
    ++t.Count;
  }
  return t;
}

// Saves a glPixelStorei parameter and restores it through vtkOpenGLState.
class ScopedPixelStore
{
public:
  ScopedPixelStore(vtkOpenGLState* state, GLenum name)
    : State(state)
    , Name(name)
  {
    glGetIntegerv(name, &this->Saved);
  }
  ~ScopedPixelStore() { this->State->vtkglPixelStorei(this->Name, this->Saved); }
  ScopedPixelStore(const ScopedPixelStore&) = delete;
  ScopedPixelStore& operator=(const ScopedPixelStore&) = delete;

private:
  vtkOpenGLState* State;
  GLenum Name;
  GLint Saved = 0;
};

// Rebinds, through the shader cache (so that the cache and OpenGL agree), the
// program that was bound when the scope began.
class ScopedProgram
{
public:
  explicit ScopedProgram(vtkOpenGLRenderWindow* win)
    : Window(win)
    , Previous(win->GetShaderCache()->GetLastShaderBound())
  {
  }
  ~ScopedProgram()
  {
    if (this->Previous && this->Previous != this->Window->GetShaderCache()->GetLastShaderBound())
    {
      this->Window->GetShaderCache()->ReadyShaderProgram(this->Previous);
    }
  }
  ScopedProgram(const ScopedProgram&) = delete;
  ScopedProgram& operator=(const ScopedProgram&) = delete;

private:
  vtkOpenGLRenderWindow* Window;
  vtkShaderProgram* Previous;
};

// All the render state of the passes, saved at construction and restored at
// destruction, with the passes' own settings applied in between.
class ScopedPassState
{
public:
  explicit ScopedPassState(vtkOpenGLState* ostate)
    : ActiveTexture(ostate)
    , Viewport(ostate)
    , ColorMask(ostate)
    , DepthTest(ostate, GL_DEPTH_TEST)
    , Blend(ostate, GL_BLEND)
    , ScissorTest(ostate, GL_SCISSOR_TEST)
    , StencilTest(ostate, GL_STENCIL_TEST)
    , CullFace(ostate, GL_CULL_FACE)
    , UnpackAlignment(ostate, GL_UNPACK_ALIGNMENT)
    , PackAlignment(ostate, GL_PACK_ALIGNMENT)
    , UnpackBuffer(GL_PIXEL_UNPACK_BUFFER, GL_PIXEL_UNPACK_BUFFER_BINDING)
    , PackBuffer(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING)
  {
    ostate->vtkglDisable(GL_DEPTH_TEST);
    ostate->vtkglDisable(GL_BLEND);
    ostate->vtkglDisable(GL_SCISSOR_TEST);
    ostate->vtkglDisable(GL_STENCIL_TEST);
    ostate->vtkglDisable(GL_CULL_FACE);
    ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    ostate->vtkglPixelStorei(GL_PACK_ALIGNMENT, 4);
  }

private:
  vtkOpenGLState::ScopedglActiveTexture ActiveTexture;
  vtkOpenGLState::ScopedglViewport Viewport;
  vtkOpenGLState::ScopedglColorMask ColorMask;
  vtkOpenGLState::ScopedglEnableDisable DepthTest;
  vtkOpenGLState::ScopedglEnableDisable Blend;
  vtkOpenGLState::ScopedglEnableDisable ScissorTest;
  vtkOpenGLState::ScopedglEnableDisable StencilTest;
  vtkOpenGLState::ScopedglEnableDisable CullFace;
  ScopedPixelStore UnpackAlignment;
  ScopedPixelStore PackAlignment;
  ScopedBufferUnbind UnpackBuffer;
  ScopedBufferUnbind PackBuffer;
};

// Keeps a texture bound to a texture unit for the scope.
class ScopedTextureActive
{
public:
  explicit ScopedTextureActive(vtkTextureObject* tex)
    : Texture(tex)
  {
    this->Texture->Activate();
  }
  ~ScopedTextureActive() { this->Texture->Deactivate(); }
  ScopedTextureActive(const ScopedTextureActive&) = delete;
  ScopedTextureActive& operator=(const ScopedTextureActive&) = delete;

private:
  vtkTextureObject* Texture;
};

int NextPowerOfTwo(int n)
{
  int p = 1;
  while (p < n)
  {
    p *= 2;
  }
  return p;
}

void SetNearestClamp(vtkTextureObject* tex)
{
  tex->SetMinificationFilter(vtkTextureObject::Nearest);
  tex->SetMagnificationFilter(vtkTextureObject::Nearest);
  tex->SetWrapS(vtkTextureObject::ClampToEdge);
  tex->SetWrapT(vtkTextureObject::ClampToEdge);
  tex->SetWrapR(vtkTextureObject::ClampToEdge);
}

// The texel size of a stored level of `size` nodes: levels are packed 2x2
// nodes (x, y) to an RGBA texel (sizes are powers of two; an axis of 1 node
// keeps 1 texel, whose odd component is then a node beyond the level).
std::array<int, 3> Packed(const std::array<int, 3>& size)
{
  return { std::max(1, size[0] / 2), std::max(1, size[1] / 2), size[2] };
}

// Where level 1 lies over the cells: its size, its factor (cells per node
// along each axis, 1 or 2) and its packed texel size, for a volume of
// `cells` cells per axis (the layout of Build(): the padded cell grid halved
// along every axis larger than 1).
struct FirstLevelLayout
{
  std::array<int, 3> Size;
  std::array<int, 3> Factor;
  std::array<int, 3> Packed;
};

FirstLevelLayout LayOutFirstLevel(const int cells[3])
{
  FirstLevelLayout layout;
  for (int a = 0; a < 3; ++a)
  {
    const int base = NextPowerOfTwo(cells[a]);
    layout.Size[a] = base > 1 ? base / 2 : 1;
    layout.Factor[a] = base / layout.Size[a];
  }
  layout.Packed = Packed(layout.Size);
  return layout;
}

// Packed texels per side of the level-1 pass's tiles (see
// vtkHistoPyramidFirstLevel_vs.glsl): 4 texels, 16 cells where the level-1
// factor is 2. Smaller tiles fit the surface more closely (on the
// 256x256x108 CT a skin or bone isovalue crosses 17-19% of the 8x8x2-cell
// tiles, 29-30% of the 16x16x2 ones, 48-50% of the 32x32x2 ones) but cost a
// primitive each: in sweeps on the CT and the 256^3 phantom, builds took
// 0.05-0.07 s and 0.11-0.13 s with 16-cell tiles, against 0.08-0.09 and
// 0.15 s with 8-cell ones and 0.08 and 0.18-0.20 s with 32-cell ones.
constexpr int TileTexels = vtkOpenGLHistoPyramid::TileNodes / 2;

// The tiles of level 1: per axis, the tile count (z: one per slice).
std::array<int, 3> TileCounts(const FirstLevelLayout& layout)
{
  return { (layout.Packed[0] + TileTexels - 1) / TileTexels,
    (layout.Packed[1] + TileTexels - 1) / TileTexels, layout.Packed[2] };
}

// The range of point values each tile of level 1 reads: out[2 t] the least
// and out[2 t + 1] the greatest value of the points of tile t's real cells
// (t = x + tiles.x (y + tiles.y z)); an empty tile (padding cells only, or
// only NaN values) gets least > greatest, which no threshold lies between.
// NaN values are left out: a cell with a NaN corner counts nothing anyway,
// and the range of the others still holds every other cell's range. R is
// the texture's type (GLint, GLuint or GLfloat), T the data's.
template <typename T, typename R>
void ComputeTileRanges(const T* data, const int points[3], const FirstLevelLayout& layout,
  const std::array<int, 3>& tiles, std::vector<R>& out)
{
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  // Cells per tile along x and y (a packed texel holds 2 nodes per axis).
  const int span[2] = { 2 * TileTexels * layout.Factor[0], 2 * TileTexels * layout.Factor[1] };
  const std::size_t perSlice = static_cast<std::size_t>(tiles[0]) * tiles[1];
  const R none = std::numeric_limits<R>::has_infinity ? std::numeric_limits<R>::infinity()
                                                      : std::numeric_limits<R>::max();
  const R noneHigh = std::numeric_limits<R>::has_infinity ? -std::numeric_limits<R>::infinity()
                                                          : std::numeric_limits<R>::lowest();
  out.assign(2 * perSlice * tiles[2], R());
  vtkSMPTools::For(0, tiles[2],
    [&](vtkIdType sliceBegin, vtkIdType sliceEnd)
    {
      std::vector<R> rowLow(tiles[0]), rowHigh(tiles[0]);
      for (vtkIdType slice = sliceBegin; slice < sliceEnd; ++slice)
      {
        R* ranges = out.data() + 2 * perSlice * slice;
        for (std::size_t t = 0; t < perSlice; ++t)
        {
          ranges[2 * t] = none;
          ranges[2 * t + 1] = noneHigh;
        }
        // The slice's cells along z, and so its points [z0, z1].
        const int z0 = static_cast<int>(slice) * layout.Factor[2];
        if (z0 >= cells[2])
        {
          continue;
        }
        const int z1 = std::min(z0 + layout.Factor[2], cells[2]);
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

// The tile ranges of `data` (of VTK type vtkType, float for converted double
// data) as the texture's type: GLint for signed integer data, GLuint for
// unsigned, GLfloat for float (each value exactly representable in it).
template <typename R>
void TileRangesAs(int vtkType, const void* data, const int points[3],
  const FirstLevelLayout& layout, const std::array<int, 3>& tiles, std::vector<R>& out)
{
  switch (vtkType)
  {
    case VTK_CHAR:
      ComputeTileRanges(static_cast<const char*>(data), points, layout, tiles, out);
      break;
    case VTK_SIGNED_CHAR:
      ComputeTileRanges(static_cast<const signed char*>(data), points, layout, tiles, out);
      break;
    case VTK_UNSIGNED_CHAR:
      ComputeTileRanges(static_cast<const unsigned char*>(data), points, layout, tiles, out);
      break;
    case VTK_SHORT:
      ComputeTileRanges(static_cast<const short*>(data), points, layout, tiles, out);
      break;
    case VTK_UNSIGNED_SHORT:
      ComputeTileRanges(static_cast<const unsigned short*>(data), points, layout, tiles, out);
      break;
    case VTK_INT:
      ComputeTileRanges(static_cast<const int*>(data), points, layout, tiles, out);
      break;
    case VTK_UNSIGNED_INT:
      ComputeTileRanges(static_cast<const unsigned int*>(data), points, layout, tiles, out);
      break;
    default: // float, and double converted to float
      ComputeTileRanges(static_cast<const float*>(data), points, layout, tiles, out);
      break;
  }
}
} // anonymous namespace

//------------------------------------------------------------------------------
// The OpenGL objects. They all live in the context of Window, the window of
// the last UploadVolume() (a weak reference: the owner releases them with
// ReleaseGraphicsResources() while the window is alive).
struct vtkOpenGLHistoPyramid::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;

  // The volume.
  vtkSmartPointer<vtkTextureObject> Volume;
  VolumeFormat Format;
  int PointDims[3] = { 0, 0, 0 };

  // The range of values under each tile of level 1 (see ComputeTileRanges()),
  // made with the volume: RG32I, RG32UI or RG32F by the volume's value type.
  vtkSmartPointer<vtkTextureObject> TileRanges;
  std::array<int, 3> Tiles = { { 0, 0, 0 } };
  std::uint64_t TilesDrawn = 0; // tiles the last Build() drew (a query)
  GLuint TileQuery = 0;         // GL_PRIMITIVES_GENERATED of the level-1 pass

  // The pyramid. Sizes[l] is the size of level l (0 = the cell grid padded to
  // powers of two); Levels[l] its texture, for l >= 1 only (the base level is
  // never stored). Each stored level has the narrowest unsigned integer
  // format that holds its largest possible count.
  std::vector<vtkSmartPointer<vtkTextureObject>> Levels;
  std::vector<std::array<int, 3>> Sizes;
  std::vector<int> BytesPerNode;
  bool Built = false;
  std::uint64_t Total = 0;
  Thresholds Current; // of the last successful Build()
  bool ChildMasks = false; // level 1 holds child masks (see GetLevelOneHoldsChildMasks())

  // The passes.
  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  // The passes' programs (owned by the window's shader cache) and the empty
  // vertex array their attribute-less layered draws need.
  vtkShaderProgram* FirstQuad = nullptr; // the level-1 pass, drawn by tiles
  vtkShaderProgram* FirstMaskQuad = nullptr; // the same, writing child masks
  vtkShaderProgram* BaseQuad = nullptr;  // ReadLevel(0) only
  ValueKind QuadKind = ValueKind::Float; // value type of FirstQuad, FirstMaskQuad and BaseQuad
  vtkShaderProgram* ReduceQuad = nullptr;
  vtkShaderProgram* ReduceMaskQuad = nullptr; // level 2 from child masks
  vtkNew<vtkOpenGLVertexArrayObject> VAO;

  void ReleaseLevels(vtkWindow* win)
  {
    for (auto& level : this->Levels)
    {
      if (level)
      {
        level->ReleaseGraphicsResources(win);
      }
    }
    this->Levels.clear();
    this->Sizes.clear();
    this->BytesPerNode.clear();
    this->Built = false;
    this->Total = 0;
    this->ChildMasks = false;
  }

  void ReleaseTiles(vtkWindow* win)
  {
    if (this->TileRanges)
    {
      this->TileRanges->ReleaseGraphicsResources(win);
      this->TileRanges = nullptr;
    }
    this->Tiles = { { 0, 0, 0 } };
    this->TilesDrawn = 0;
  }

  static void ReleaseQuad(vtkWindow* win, vtkShaderProgram*& program)
  {
    // The programs belong to the window's shader cache: free their GL
    // objects so that the cache recompiles them if they are asked for again.
    if (program)
    {
      program->ReleaseGraphicsResources(win);
    }
    program = nullptr;
  }

  void ReleaseAll(vtkWindow* win)
  {
    this->ReleaseLevels(win);
    if (this->Volume)
    {
      this->Volume->ReleaseGraphicsResources(win);
      this->Volume = nullptr;
    }
    this->PointDims[0] = this->PointDims[1] = this->PointDims[2] = 0;
    this->ReleaseTiles(win);
    ReleaseQuad(win, this->FirstQuad);
    ReleaseQuad(win, this->FirstMaskQuad);
    ReleaseQuad(win, this->BaseQuad);
    ReleaseQuad(win, this->ReduceQuad);
    ReleaseQuad(win, this->ReduceMaskQuad);
    if (this->TileQuery && this->Window) // (a query made in a window gone went with it)
    {
      glDeleteQueries(1, &this->TileQuery);
    }
    this->TileQuery = 0;
    this->VAO->ReleaseGraphicsResources();
    if (this->FBO)
    {
      this->FBO->ReleaseGraphicsResources(win);
      this->FBO = nullptr;
    }
    this->Window = nullptr;
  }

  // The value-type #defines and the shared crossing code of the volume.
  std::string Declarations() const
  {
    return std::string(ValueTypeDefines(this->Format.Kind)) + vtkHistoPyramidCommon;
  }

  // A pass fragment shader with the shared declarations put in.
  std::string PassShader(const char* source) const
  {
    std::string fs = source;
    vtkShaderProgram::Substitute(fs, "//VTK::HistoPyramidCommon::Dec", this->Declarations());
    return fs;
  }

  // A pass that writes a stored level: the packed layout's main() put in.
  static std::string PackedPass(const std::string& source)
  {
    std::string fs = source;
    vtkShaderProgram::Substitute(fs, "//VTK::HistoPyramidPacked::Impl", vtkHistoPyramidPacked);
    return fs;
  }

  // A shader with `define` (a macro name) defined after its version line.
  // The pass variants are compiled apart, not chosen by a uniform: a
  // software rasteriser runs both sides of a branch under SIMD masks.
  static std::string WithDefine(std::string source, const char* define)
  {
    vtkShaderProgram::Substitute(source, "//VTK::System::Dec",
      std::string("//VTK::System::Dec\n#define ") + define + "\n");
    return source;
  }

  // Ready (compile or rebind) a pass program: the layered full-screen quads
  // with fragment shader `fs`. Returns the bound program, or nullptr when it
  // does not build.
  static vtkShaderProgram* ReadyPass(
    vtkOpenGLRenderWindow* win, vtkShaderProgram*& program, const std::string& fs)
  {
    program = win->GetShaderCache()->ReadyShaderProgram(
      vtkHistoPyramidLayer_vs, fs.c_str(), vtkHistoPyramidLayer_gs);
    return program;
  }

  // Ready the level-1 pass: the tiles of vtkHistoPyramidFirstLevel_vs.glsl,
  // made quads on their slices by vtkHistoPyramidFirstLevel_gs.glsl.
  // With childMasks, the variant that writes child masks (see
  // GetLevelOneHoldsChildMasks()).
  vtkShaderProgram* ReadyFirstLevelPass(vtkOpenGLRenderWindow* win, bool childMasks)
  {
    std::string fs = this->PassShader(vtkHistoPyramidFirstLevel_fs);
    if (childMasks)
    {
      fs = WithDefine(fs, "MEDISO_CHILD_MASKS");
    }
    const std::string vs = this->PassShader(vtkHistoPyramidFirstLevel_vs);
    vtkShaderProgram*& program = childMasks ? this->FirstMaskQuad : this->FirstQuad;
    program = win->GetShaderCache()->ReadyShaderProgram(
      vs.c_str(), fs.c_str(), vtkHistoPyramidFirstLevel_gs);
    return program;
  }

  // All `slices` z-slices of the layered attachment, in one draw call.
  void DrawSlices(int slices)
  {
    this->VAO->Bind();
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, slices);
    this->VAO->Release();
  }

  // Set the uniforms of vtkHistoPyramidCommon.glsl on the bound program; the
  // volume texture must be active.
  void SetCommonUniforms(vtkShaderProgram* program, const Thresholds& t) const
  {
    program->SetUniformi("volume", this->Volume->GetTextureUnit());
    program->SetUniformi("numberOfThresholds", t.Count);
    const int cells[3] = { this->PointDims[0] - 1, this->PointDims[1] - 1,
      this->PointDims[2] - 1 };
    SetUniformIVec3(program, "cellDimensions", cells);
    const GLint location = program->FindUniform("thresholds");
    if (t.Count > 0 && location >= 0)
    {
      switch (this->Format.Kind)
      {
        case ValueKind::Signed:
          glUniform1iv(location, t.Count, t.Ints.data());
          break;
        case ValueKind::Unsigned:
          glUniform1uiv(location, t.Count, t.UInts.data());
          break;
        case ValueKind::Float:
          glUniform1fv(location, t.Count, t.Floats.data());
          break;
      }
    }
  }

  // Make the quad programs of the volume's value type current (dropping those
  // of another type).
  void MatchQuadKind(vtkWindow* win)
  {
    if (this->QuadKind != this->Format.Kind)
    {
      ReleaseQuad(win, this->FirstQuad);
      ReleaseQuad(win, this->FirstMaskQuad);
      ReleaseQuad(win, this->BaseQuad);
      this->QuadKind = this->Format.Kind;
    }
  }
};

//------------------------------------------------------------------------------
vtkOpenGLHistoPyramid::vtkOpenGLHistoPyramid()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkOpenGLHistoPyramid::~vtkOpenGLHistoPyramid()
{
  // Owners normally call ReleaseGraphicsResources() first; if they did not and
  // the window is still alive, free the OpenGL objects in its context.
  if (this->Impl->Window)
  {
    ScopedContext context(this->Impl->Window);
    this->Impl->ReleaseAll(this->Impl->Window);
  }
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramid::GetTotal() const
{
  return this->Impl->Built ? this->Impl->Total : 0;
}

//------------------------------------------------------------------------------
int vtkOpenGLHistoPyramid::GetNumberOfLevels() const
{
  return this->Impl->Built ? static_cast<int>(this->Impl->Sizes.size()) : 0;
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::GetLevelSize(int level, int size[3]) const
{
  const Internals& impl = *this->Impl;
  if (!impl.Built || level < 0 || level >= static_cast<int>(impl.Sizes.size()))
  {
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    size[a] = impl.Sizes[level][a];
  }
  return true;
}

//------------------------------------------------------------------------------
vtkTextureObject* vtkOpenGLHistoPyramid::GetLevelTexture(int level) const
{
  const Internals& impl = *this->Impl;
  if (!impl.Built || level < 1 || level >= static_cast<int>(impl.Levels.size()))
  {
    return nullptr;
  }
  return impl.Levels[level];
}

//------------------------------------------------------------------------------
vtkTextureObject* vtkOpenGLHistoPyramid::GetVolumeTexture() const
{
  return this->Impl->Volume;
}

//------------------------------------------------------------------------------
std::string vtkOpenGLHistoPyramid::GetShaderDeclarations() const
{
  return this->Impl->Declarations();
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramid::SetShaderUniforms(vtkShaderProgram* program) const
{
  const Internals& impl = *this->Impl;
  if (program && impl.Volume && impl.Built)
  {
    impl.SetCommonUniforms(program, impl.Current);
  }
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::GetLevelOneHoldsChildMasks() const
{
  return this->Impl->Built && this->Impl->ChildMasks;
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramid::GetNumberOfTiles() const
{
  const Internals& impl = *this->Impl;
  return static_cast<std::uint64_t>(impl.Tiles[0]) * impl.Tiles[1] * impl.Tiles[2];
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramid::GetLastTilesDrawn() const
{
  return this->Impl->Built ? this->Impl->TilesDrawn : 0;
}

//------------------------------------------------------------------------------
std::vector<int> vtkOpenGLHistoPyramid::GetCountedIsovalues() const
{
  return this->Impl->Built ? this->Impl->Current.Indices : std::vector<int>();
}

//------------------------------------------------------------------------------
std::uint64_t vtkOpenGLHistoPyramid::GetGPUMemoryBytes() const
{
  const Internals& impl = *this->Impl;
  std::uint64_t bytes = 0;
  if (impl.Volume)
  {
    bytes += static_cast<std::uint64_t>(4 * PackedVolumeWidth(impl.PointDims[0])) *
      impl.PointDims[1] * impl.PointDims[2] * impl.Format.BytesPerValue;
  }
  if (impl.TileRanges)
  {
    bytes += static_cast<std::uint64_t>(impl.Tiles[0]) * impl.Tiles[1] * impl.Tiles[2] * 8;
  }
  for (std::size_t l = 1; l < impl.Levels.size(); ++l)
  {
    const std::array<int, 3> packed = Packed(impl.Sizes[l]);
    bytes += static_cast<std::uint64_t>(packed[0]) * packed[1] * packed[2] * 4 * impl.BytesPerNode[l];
  }
  return bytes;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramid::ReleaseGraphicsResources(vtkWindow* win)
{
  // Release in the context the objects were made in, whatever is current.
  if (this->Impl->Window)
  {
    ScopedContext context(this->Impl->Window);
    this->Impl->ReleaseAll(this->Impl->Window);
  }
  else
  {
    this->Impl->ReleaseAll(win);
  }
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::UploadVolume(
  vtkOpenGLRenderWindow* renWin, vtkDataArray* scalars, const int pointDims[3])
{
  Internals& impl = *this->Impl;
  if (!renWin || !scalars || !pointDims)
  {
    vtkErrorMacro("UploadVolume needs a window, an array and dimensions.");
    return false;
  }
  if (pointDims[0] < 2 || pointDims[1] < 2 || pointDims[2] < 2)
  {
    vtkErrorMacro("The volume must have at least 2 points per axis, not "
      << pointDims[0] << "x" << pointDims[1] << "x" << pointDims[2] << ".");
    return false;
  }
  const vtkIdType numPoints = static_cast<vtkIdType>(pointDims[0]) * pointDims[1] * pointDims[2];
  if (scalars->GetNumberOfComponents() != 1 || scalars->GetNumberOfTuples() != numPoints)
  {
    vtkErrorMacro("Expected " << numPoints << " single-component values, got "
                              << scalars->GetNumberOfTuples() << " tuples of "
                              << scalars->GetNumberOfComponents() << " components.");
    return false;
  }
  VolumeFormat format;
  if (!ChooseFormat(scalars->GetDataType(), format))
  {
    vtkErrorMacro("Unsupported scalar type " << scalars->GetDataTypeAsString() << ".");
    return false;
  }
  if (impl.Window && impl.Window != renWin)
  {
    ScopedContext oldContext(impl.Window);
    impl.ReleaseAll(impl.Window);
  }

  // Double data is converted to float; every other type goes up as it is.
  std::vector<float> converted;
  void* data = scalars->GetVoidPointer(0);
  if (scalars->GetDataType() == VTK_DOUBLE)
  {
    const double* d = static_cast<const double*>(data);
    converted.assign(d, d + numPoints);
    data = converted.data();
  }

  ScopedContext context(renWin);
  vtkOpenGLState* ostate = renWin->GetState();
  TakeGLErrors();
  ScopedPassState savedState(ostate);

  // A new size invalidates the levels (and a new window everything, above).
  const bool sameSize = impl.PointDims[0] == pointDims[0] && impl.PointDims[1] == pointDims[1] &&
    impl.PointDims[2] == pointDims[2];
  if (!sameSize)
  {
    impl.ReleaseLevels(renWin);
  }
  impl.Built = false;
  impl.Total = 0;
  if (impl.Volume)
  {
    impl.Volume->ReleaseGraphicsResources(renWin);
  }
  impl.ReleaseTiles(renWin);
  impl.Window = renWin;
  impl.Volume = vtkSmartPointer<vtkTextureObject>::New();
  impl.Volume->SetContext(renWin);
  impl.Volume->SetInternalFormat(format.InternalFormat);
  impl.Volume->SetFormat(format.Format);
  impl.Volume->SetDataType(format.DataType);
  SetNearestClamp(impl.Volume);
  std::vector<unsigned char> packed;
  if (pointDims[0] % 4 != 0)
  {
    packed = PackVolumeRows(data, pointDims, format.BytesPerValue);
  }
  const bool created =
    impl.Volume->Create3DFromRaw(static_cast<unsigned int>(PackedVolumeWidth(pointDims[0])),
      static_cast<unsigned int>(pointDims[1]), static_cast<unsigned int>(pointDims[2]), 4,
      format.UploadVTKType, packed.empty() ? data : packed.data());
  packed = std::vector<unsigned char>();
  const std::string errors = TakeGLErrors();
  if (!created || !errors.empty())
  {
    vtkErrorMacro("Cannot upload the " << pointDims[0] << "x" << pointDims[1] << "x" << pointDims[2]
                                       << " volume as a 3D texture"
                                       << (errors.empty() ? "" : ": " + errors));
    impl.Volume->ReleaseGraphicsResources(renWin);
    impl.Volume = nullptr;
    impl.PointDims[0] = impl.PointDims[1] = impl.PointDims[2] = 0;
    return false;
  }

  // The value range under each tile of level 1, which lets the level-1 pass
  // draw only the tiles an isovalue can cross.
  const int cells[3] = { pointDims[0] - 1, pointDims[1] - 1, pointDims[2] - 1 };
  const FirstLevelLayout layout = LayOutFirstLevel(cells);
  const std::array<int, 3> tiles = TileCounts(layout);
  std::vector<GLint> intRanges;
  std::vector<GLuint> uintRanges;
  std::vector<GLfloat> floatRanges;
  const int dataType = scalars->GetDataType() == VTK_DOUBLE ? VTK_FLOAT : scalars->GetDataType();
  void* ranges = nullptr;
  GLenum rangeFormat = GL_RG32F, rangeDataType = GL_FLOAT;
  int rangeVTKType = VTK_FLOAT;
  switch (format.Kind)
  {
    case ValueKind::Signed:
      TileRangesAs(dataType, data, pointDims, layout, tiles, intRanges);
      ranges = intRanges.data();
      rangeFormat = GL_RG32I;
      rangeDataType = GL_INT;
      rangeVTKType = VTK_INT;
      break;
    case ValueKind::Unsigned:
      TileRangesAs(dataType, data, pointDims, layout, tiles, uintRanges);
      ranges = uintRanges.data();
      rangeFormat = GL_RG32UI;
      rangeDataType = GL_UNSIGNED_INT;
      rangeVTKType = VTK_UNSIGNED_INT;
      break;
    case ValueKind::Float:
      TileRangesAs(dataType, data, pointDims, layout, tiles, floatRanges);
      ranges = floatRanges.data();
      break;
  }
  impl.TileRanges = vtkSmartPointer<vtkTextureObject>::New();
  impl.TileRanges->SetContext(renWin);
  impl.TileRanges->SetInternalFormat(rangeFormat);
  impl.TileRanges->SetFormat(format.Kind == ValueKind::Float ? GL_RG : GL_RG_INTEGER);
  impl.TileRanges->SetDataType(rangeDataType);
  SetNearestClamp(impl.TileRanges);
  const bool tilesCreated =
    impl.TileRanges->Create3DFromRaw(static_cast<unsigned int>(tiles[0]),
      static_cast<unsigned int>(tiles[1]), static_cast<unsigned int>(tiles[2]), 2, rangeVTKType,
      ranges);
  const std::string tileErrors = TakeGLErrors();
  if (!tilesCreated || !tileErrors.empty())
  {
    vtkErrorMacro("Cannot upload the " << tiles[0] << "x" << tiles[1] << "x" << tiles[2]
                                       << " tile ranges of the volume"
                                       << (tileErrors.empty() ? "" : ": " + tileErrors));
    impl.ReleaseTiles(renWin);
    impl.Volume->ReleaseGraphicsResources(renWin);
    impl.Volume = nullptr;
    impl.PointDims[0] = impl.PointDims[1] = impl.PointDims[2] = 0;
    return false;
  }
  impl.Tiles = tiles;
  impl.Format = format;
  impl.MatchQuadKind(renWin);
  for (int a = 0; a < 3; ++a)
  {
    impl.PointDims[a] = pointDims[a];
  }
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::Build(
  vtkOpenGLRenderWindow* renWin, const std::vector<double>& isovalues)
{
  Internals& impl = *this->Impl;
  impl.Built = false;
  impl.Total = 0;
  if (!renWin || !impl.Volume || impl.Window != renWin)
  {
    vtkErrorMacro("Build needs a volume uploaded to the same window first.");
    return false;
  }
  if (isovalues.empty() || isovalues.size() > static_cast<std::size_t>(MaximumNumberOfIsovalues))
  {
    vtkErrorMacro("Build takes 1 to " << MaximumNumberOfIsovalues << " isovalues, not "
                                      << isovalues.size() << ".");
    return false;
  }
  const Thresholds thresholds = MakeThresholds(impl.Format, isovalues);

  ScopedContext context(renWin);
  vtkOpenGLState* ostate = renWin->GetState();
  TakeGLErrors();
  ScopedProgram savedProgram(renWin);
  ScopedPassState savedState(ostate);

  // 1. The level textures, allocated once per volume size. Level 0 (the
  //    padded cell grid) only has a size; levels 1.. are textures. Even a
  //    single cell gets a level 1 (1x1x1), so that there is always one.
  const int cells[3] = { impl.PointDims[0] - 1, impl.PointDims[1] - 1, impl.PointDims[2] - 1 };
  if (impl.Sizes.empty())
  {
    std::array<int, 3> size = { NextPowerOfTwo(cells[0]), NextPowerOfTwo(cells[1]),
      NextPowerOfTwo(cells[2]) };
    const std::array<int, 3> base = size;
    impl.Sizes.push_back(size);
    impl.Levels.emplace_back(nullptr);
    impl.BytesPerNode.push_back(0);
    do
    {
      for (int& s : size)
      {
        s = s > 1 ? s / 2 : 1;
      }
      // The largest count of a node: every isovalue crossing every cell under it.
      const double maxCount = static_cast<double>(MaximumNumberOfIsovalues) * (base[0] / size[0]) *
        (base[1] / size[1]) * (base[2] / size[2]);
      GLenum internalFormat = GL_RGBA32UI, dataType = GL_UNSIGNED_INT;
      int bytes = 4, vtkType = VTK_UNSIGNED_INT;
      if (maxCount <= 255.0)
      {
        internalFormat = GL_RGBA8UI;
        dataType = GL_UNSIGNED_BYTE;
        bytes = 1;
        vtkType = VTK_UNSIGNED_CHAR;
      }
      else if (maxCount <= 65535.0)
      {
        internalFormat = GL_RGBA16UI;
        dataType = GL_UNSIGNED_SHORT;
        bytes = 2;
        vtkType = VTK_UNSIGNED_SHORT;
      }
      auto level = vtkSmartPointer<vtkTextureObject>::New();
      level->SetContext(renWin);
      level->SetInternalFormat(internalFormat);
      level->SetFormat(GL_RGBA_INTEGER);
      level->SetDataType(dataType);
      SetNearestClamp(level);
      const std::array<int, 3> packed = Packed(size);
      if (!level->Allocate3D(static_cast<unsigned int>(packed[0]),
            static_cast<unsigned int>(packed[1]), static_cast<unsigned int>(packed[2]), 4, vtkType))
      {
        vtkErrorMacro("Cannot allocate a " << packed[0] << "x" << packed[1] << "x" << packed[2]
                                           << " RGBA integer 3D texture: " << TakeGLErrors());
        impl.ReleaseLevels(renWin);
        return false;
      }
      impl.Levels.push_back(level);
      impl.Sizes.push_back(size);
      impl.BytesPerNode.push_back(bytes);
    } while (size[0] > 1 || size[1] > 1 || size[2] > 1);
  }
  const int numLevels = static_cast<int>(impl.Sizes.size());
  // One isovalue: level 1 holds each node's child mask, whose bits the
  // reduction to level 2 counts (with a level 2 to count them: a volume of at
  // most 2 cells per axis has level 1 on top, whose node must be the total).
  const bool childMasks = thresholds.Count == 1 && numLevels >= 3;
  vtkShaderProgram* firstProgram = impl.ReadyFirstLevelPass(renWin, childMasks);
  vtkShaderProgram* reduceProgram =
    Internals::ReadyPass(renWin, impl.ReduceQuad, Internals::PackedPass(vtkHistoPyramidReduce_fs));
  vtkShaderProgram* reduceMaskProgram = childMasks
    ? Internals::ReadyPass(renWin, impl.ReduceMaskQuad,
        Internals::WithDefine(
          Internals::PackedPass(vtkHistoPyramidReduce_fs), "MEDISO_LOWER_CHILD_MASKS"))
    : reduceProgram;
  if (!firstProgram || !reduceProgram || !reduceMaskProgram)
  {
    vtkErrorMacro("The HistoPyramid shaders do not build.");
    return false;
  }

  // 3. The framebuffer: one level attached at a time, all its slices as
  //    layers (gl_Layer selects the slice).
  if (!impl.FBO)
  {
    impl.FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    impl.FBO->SetContext(renWin);
  }
  ScopedFramebufferBindings savedBindings(impl.FBO);
  impl.FBO->Bind();
  impl.FBO->ActivateDrawBuffers(1);
  impl.FBO->ActivateReadBuffer(0);
  auto attach = [&](vtkTextureObject* texture) -> bool
  {
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, texture->GetHandle(), 0);
    {
      const char* desc = nullptr;
      if (!vtkOpenGLFramebufferObject::GetFrameBufferStatus(GL_FRAMEBUFFER, desc))
      {
        vtkErrorMacro("An integer render target of the HistoPyramid is incomplete: "
          << (desc ? desc : "unknown status"));
        return false;
      }
    }
    return true;
  };
  struct Detach
  {
    ~Detach() { glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, 0, 0); }
  } detachOnExit;

  // Make level l the target of `program`: the uniforms of the layout (level
  // l's size and its factor over level l - 1), the viewport, the attachment.
  // drawLevel() then draws every z-slice in one layered draw; the level-1
  // pass draws its tiles instead.
  auto targetLevel = [&](vtkShaderProgram* program, int l) -> bool
  {
    const auto& size = impl.Sizes[l];
    const auto& lower = impl.Sizes[l - 1];
    const int factor[3] = { lower[0] / size[0], lower[1] / size[1], lower[2] / size[2] };
    const std::array<int, 3> packed = Packed(size);
    const int sliceSize[2] = { packed[0], packed[1] };
    SetUniformIVec3(program, "factor", factor);
    program->SetUniform2i("sliceSize", sliceSize);
    SetUniformIVec3(program, "levelSize", size.data());
    ostate->vtkglViewport(0, 0, packed[0], packed[1]);
    return attach(impl.Levels[l]);
  };
  auto drawLevel = [&](vtkShaderProgram* program, int l) -> bool
  {
    if (!targetLevel(program, l))
    {
      return false;
    }
    impl.DrawSlices(impl.Sizes[l][2]);
    return true;
  };

  // 4. Level 1 from the volume: cleared to 0, then only the tiles whose value
  //    range holds an isovalue are drawn (one point per tile and slice; the
  //    geometry stage drops the others).
  {
    renWin->GetShaderCache()->ReadyShaderProgram(firstProgram);
    ScopedTextureActive volumeActive(impl.Volume);
    ScopedTextureActive rangesActive(impl.TileRanges);
    impl.SetCommonUniforms(firstProgram, thresholds);
    firstProgram->SetUniformi("tileRanges", impl.TileRanges->GetTextureUnit());
    const int tiles[2] = { impl.Tiles[0], impl.Tiles[1] };
    firstProgram->SetUniform2i("tiles", tiles);
    firstProgram->SetUniformi("tileSize", TileTexels);
    if (!targetLevel(firstProgram, 1))
    {
      return false;
    }
    const GLuint zero[4] = { 0, 0, 0, 0 };
    glClearBufferuiv(GL_COLOR, 0, zero);
    if (!impl.TileQuery)
    {
      glGenQueries(1, &impl.TileQuery);
    }
    glBeginQuery(GL_PRIMITIVES_GENERATED, impl.TileQuery);
    impl.VAO->Bind();
    glDrawArrays(GL_POINTS, 0, impl.Tiles[0] * impl.Tiles[1] * impl.Tiles[2]);
    impl.VAO->Release();
    glEndQuery(GL_PRIMITIVES_GENERATED);
  }

  // 5. Reduction passes: level l from level l - 1 (level 2 from child masks
  //    by its own variant).
  for (int l = 2; l < numLevels; ++l)
  {
    vtkShaderProgram* program = l == 2 ? reduceMaskProgram : reduceProgram;
    renWin->GetShaderCache()->ReadyShaderProgram(program);
    ScopedTextureActive lowerActive(impl.Levels[l - 1]);
    program->SetUniformi("lowerLevel", impl.Levels[l - 1]->GetTextureUnit());
    if (!drawLevel(program, l))
    {
      return false;
    }
  }

  // 6. Read back the top node only (component 0 of the top level's texel).
  GLuint top[4] = { 0, 0, 0, 0 };
  if (!attach(impl.Levels[numLevels - 1]))
  {
    return false;
  }
  glReadPixels(0, 0, 1, 1, GL_RGBA_INTEGER, GL_UNSIGNED_INT, top);
  const std::string errors = TakeGLErrors();
  if (!errors.empty())
  {
    vtkErrorMacro("Building the HistoPyramid failed: " << errors);
    return false;
  }
  // Each tile drawn is a strip of two triangles. (The draw is done: the
  // read-back above waited for it.)
  GLuint primitives = 0;
  glGetQueryObjectuiv(impl.TileQuery, GL_QUERY_RESULT, &primitives);
  impl.TilesDrawn = primitives / 2;
  impl.Total = top[0];
  impl.Current = thresholds;
  impl.ChildMasks = childMasks;
  impl.Built = true;
  return true;
}

//------------------------------------------------------------------------------
bool vtkOpenGLHistoPyramid::ReadLevel(
  int level, std::vector<std::uint32_t>& counts, int size[3], bool asStored)
{
  Internals& impl = *this->Impl;
  if (!impl.Built || level < 0 || level >= static_cast<int>(impl.Sizes.size()) || !impl.Window)
  {
    return false;
  }
  const auto& s = impl.Sizes[level];
  for (int a = 0; a < 3; ++a)
  {
    size[a] = s[a];
  }
  counts.assign(static_cast<std::size_t>(s[0]) * s[1] * s[2], 0u);

  vtkOpenGLRenderWindow* win = impl.Window;
  ScopedContext context(win);
  TakeGLErrors();
  ScopedProgram savedProgram(win);
  ScopedPassState savedState(win->GetState());
  ScopedFramebufferBindings savedBindings(impl.FBO);
  impl.FBO->Bind();
  impl.FBO->ActivateDrawBuffers(1);
  impl.FBO->ActivateReadBuffer(0);

  // The base level is not stored: draw it into a temporary texture first.
  vtkSmartPointer<vtkTextureObject> texture = level > 0 ? impl.Levels[level] : nullptr;
  if (level == 0)
  {
    vtkShaderProgram* baseProgram =
      Internals::ReadyPass(win, impl.BaseQuad, impl.PassShader(vtkHistoPyramidBase_fs));
    texture = vtkSmartPointer<vtkTextureObject>::New();
    texture->SetContext(win);
    texture->SetInternalFormat(GL_R32UI);
    texture->SetFormat(GL_RED_INTEGER);
    texture->SetDataType(GL_UNSIGNED_INT);
    SetNearestClamp(texture);
    if (!baseProgram ||
      !texture->Allocate3D(static_cast<unsigned int>(s[0]), static_cast<unsigned int>(s[1]),
        static_cast<unsigned int>(s[2]), 1, VTK_UNSIGNED_INT))
    {
      vtkErrorMacro("Cannot draw the base level for reading: " << TakeGLErrors());
      return false;
    }
    ScopedTextureActive volumeActive(impl.Volume);
    impl.SetCommonUniforms(baseProgram, impl.Current);
    const int sliceSize[2] = { s[0], s[1] };
    baseProgram->SetUniform2i("sliceSize", sliceSize);
    win->GetState()->vtkglViewport(0, 0, s[0], s[1]);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, texture->GetHandle(), 0);
    impl.DrawSlices(s[2]);
  }
  const std::size_t sliceCount = static_cast<std::size_t>(s[0]) * s[1];
  const std::array<int, 3> packed = Packed(s);
  std::vector<GLuint> texels(4 * static_cast<std::size_t>(packed[0]) * packed[1]);
  // Level 1 holding child masks comes back as their counts of set bits.
  const bool countBits = level == 1 && impl.ChildMasks && !asStored;
  for (int z = 0; z < s[2]; ++z)
  {
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, texture->GetHandle(), 0, z);
    if (level == 0)
    {
      glReadPixels(
        0, 0, s[0], s[1], GL_RED_INTEGER, GL_UNSIGNED_INT, counts.data() + z * sliceCount);
      continue;
    }
    // Stored levels are packed: node (x, y) is component (x & 1) + 2 (y & 1)
    // of texel (x / 2, y / 2).
    glReadPixels(0, 0, packed[0], packed[1], GL_RGBA_INTEGER, GL_UNSIGNED_INT, texels.data());
    for (int y = 0; y < s[1]; ++y)
    {
      for (int x = 0; x < s[0]; ++x)
      {
        const std::size_t texel = static_cast<std::size_t>(y / 2) * packed[0] + x / 2;
        const GLuint node = texels[4 * texel + (x & 1) + 2 * (y & 1)];
        counts[z * sliceCount + static_cast<std::size_t>(y) * s[0] + x] = countBits
          ? static_cast<std::uint32_t>(std::bitset<8>(node).count())
          : static_cast<std::uint32_t>(node);
      }
    }
  }
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, 0, 0, 0);
  if (level == 0)
  {
    texture->ReleaseGraphicsResources(win);
  }
  const std::string errors = TakeGLErrors();
  if (!errors.empty())
  {
    vtkErrorMacro("Reading level " << level << " back failed: " << errors);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkOpenGLHistoPyramid::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  const Internals& impl = *this->Impl;
  os << indent << "Volume: " << impl.PointDims[0] << "x" << impl.PointDims[1] << "x"
     << impl.PointDims[2] << " points\n";
  os << indent << "NumberOfLevels: " << this->GetNumberOfLevels() << "\n";
  os << indent << "Total: " << this->GetTotal() << "\n";
  os << indent << "GPUMemoryBytes: " << this->GetGPUMemoryBytes() << "\n";
}
