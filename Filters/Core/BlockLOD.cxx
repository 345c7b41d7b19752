// SPDX-License-Identifier: BSD-3-Clause
#include "BlockLOD.h"

#include "ScalarTypes.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace mediso
{
namespace
{
// Cube corners in vtkMarchingCubes' order.
constexpr int CornerOffset[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 },
  { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
// Cube edges as (lower corner, upper corner), vtkMarchingCubes' numbering.
constexpr int EdgeCorners[12][2] = { { 0, 1 }, { 1, 2 }, { 3, 2 }, { 0, 3 }, { 4, 5 }, { 5, 6 },
  { 7, 6 }, { 4, 7 }, { 0, 4 }, { 1, 5 }, { 3, 7 }, { 2, 6 } };

int EdgeAxis(int edge)
{
  const int* a = CornerOffset[EdgeCorners[edge][0]];
  const int* b = CornerOffset[EdgeCorners[edge][1]];
  return a[0] != b[0] ? 0 : (a[1] != b[1] ? 1 : 2);
}

// Number of triangles of each case of a table.
struct TriangleCounts
{
  int Count[256];
  explicit TriangleCounts(TriangleCaseTable cases)
  {
    for (int c = 0; c < 256; ++c)
    {
      int n = 0;
      while (n < 5 && cases[c][3 * n] >= 0)
      {
        ++n;
      }
      this->Count[c] = n;
    }
  }
};

// A sample that is no number to contour: NaN or infinite. Never for integer
// types (the test is compiled away).
template <typename T>
inline bool IsMissing(T v)
{
  if constexpr (std::is_floating_point<T>::value)
  {
    return !std::isfinite(v);
  }
  else
  {
    return false;
  }
}

// The samples of one block at one level (see BlockLOD.h), and the block's
// bit layouts: cut edges as bit Axis * L^3 + (k * L + j) * L + i of a mask of
// L = 8 / stride + 1 samples per axis (one plane of bits per axis, so that a
// row of samples' x-, y- or z-edges is a run of bits), cubes as bit
// (k * C + j) * C + i of C = 8 / stride cubes per axis.
struct BlockSamples
{
  int First[3];
  int Last[3];
  int Count[3]; // samples along each axis (cubes = Count - 1)
  bool LastBlock[3];
  int Stride;
  int Layout;      // L
  int LayoutCube;  // L^3: bits per axis plane
  int CubeShift;   // log2(C)

  BlockSamples(const BlockRanges& ranges, std::int64_t block, int stride)
    : Stride(stride)
    , Layout(BlockCells / stride + 1)
    , LayoutCube(Layout * Layout * Layout)
    , CubeShift(stride == 1 ? 3 : (stride == 2 ? 2 : (stride == 4 ? 1 : 0)))
  {
    const std::int64_t b[3] = { block % ranges.Blocks[0],
      (block / ranges.Blocks[0]) % ranges.Blocks[1],
      block / (static_cast<std::int64_t>(ranges.Blocks[0]) * ranges.Blocks[1]) };
    for (int a = 0; a < 3; ++a)
    {
      this->First[a] = static_cast<int>(b[a]) * BlockCells;
      this->Last[a] = std::min(this->First[a] + BlockCells, ranges.Dims[a] - 1);
      this->Count[a] = (this->Last[a] - this->First[a] + stride - 1) / stride + 1;
      this->LastBlock[a] = b[a] == ranges.Blocks[a] - 1;
    }
  }
  int Point(int axis, int sample) const
  {
    return std::min(this->First[axis] + sample * this->Stride, this->Last[axis]);
  }
  int Bit(int i, int j, int k, int axis) const
  {
    return axis * this->LayoutCube + (k * this->Layout + j) * this->Layout + i;
  }
  // Samples along an axis whose edges (to the next sample) this block owns:
  // all but the last, unless the block is the volume's last along the axis.
  int Own(int axis) const
  {
    return this->LastBlock[axis] ? this->Count[axis] : this->Count[axis] - 1;
  }
};

int LayoutOf(int level)
{
  return BlockCells / LevelStride(level) + 1;
}

int WordsPerBlock(int level)
{
  const int layout = LayoutOf(level);
  return (3 * layout * layout * layout + 63) / 64;
}

int CubeWordsPerBlock(int level)
{
  const int cubes = BlockCells / LevelStride(level);
  return (cubes * cubes * cubes + 63) / 64;
}

inline int PopCount64(std::uint64_t x)
{
#if defined(__POPCNT__)
  return __builtin_popcountll(x);
#else
  // Without the POPCNT instruction (x86-64 baseline) the builtin is a libgcc
  // call; this SWAR count is inlined.
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<int>((x * 0x0101010101010101ull) >> 56);
#endif
}

// Transposes an 8 x 8 bit matrix held in 64 bits (bit 8 r + c is row r,
// column c): Hacker's Delight, "Transposing a Bit Matrix".
inline std::uint64_t TransposeBits8x8(std::uint64_t x)
{
  std::uint64_t t = (x ^ (x >> 7)) & 0x00AA00AA00AA00AAull;
  x = x ^ t ^ (t << 7);
  t = (x ^ (x >> 14)) & 0x0000CCCC0000CCCCull;
  x = x ^ t ^ (t << 14);
  t = (x ^ (x >> 28)) & 0x00000000F0F0F0F0ull;
  return x ^ t ^ (t << 28);
}

// ORs a run of at most 16 bits into a bit mask at bit `at`.
inline void OrBits(std::uint64_t* words, int at, std::uint32_t run)
{
  const int shift = at & 63;
  words[at >> 6] |= static_cast<std::uint64_t>(run) << shift;
  if (shift > 48)
  {
    // Past this word only when the run reaches beyond bit 63 (then the next
    // word belongs to the same mask).
    const std::uint64_t high = static_cast<std::uint64_t>(run) >> (64 - shift);
    if (high)
    {
      words[(at >> 6) + 1] |= high;
    }
  }
}

// "value >= isovalue" for a sample type. For integer types the test is
// v >= ceil(isovalue) in integers (no conversion of every sample to double).
template <typename T>
class AboveIsovalue
{
public:
  explicit AboveIsovalue(double isovalue)
    : Isovalue(isovalue)
  {
    if constexpr (std::is_integral<T>::value)
    {
      const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
      const double hi = static_cast<double>(std::numeric_limits<T>::max()) + 1.0; // never reached
      const double c = std::ceil(isovalue);
      this->Threshold = static_cast<std::int64_t>(c == c ? std::min(hi, std::max(lo, c)) : hi);
    }
  }
  /// For integer types: v >= IntegerThreshold() (ceil(isovalue), clamped to
  /// [lowest, max + 1]).
  std::int64_t IntegerThreshold() const { return this->Threshold; }
  bool operator()(T v) const
  {
    if constexpr (std::is_integral<T>::value)
    {
      return static_cast<std::int64_t>(v) >= this->Threshold;
    }
    else
    {
      return static_cast<double>(v) >= this->Isovalue;
    }
  }

private:
  double Isovalue;
  std::int64_t Threshold = 0;
};

// A block's samples classified against the isovalue, one bit mask per row of
// samples along x: bit i of row (j, k) is sample i.
struct BlockRows
{
  std::uint16_t Above[BlockCells + 1][BlockCells + 1];   // [k][j]: value >= isovalue
  std::uint16_t Missing[BlockCells + 1][BlockCells + 1]; // [k][j]: NaN or infinite
};

// The "above" bits of a full row of a block at full resolution (9 samples)
// in a few vector instructions, for the types of the scans (8-bit MRI, 16-bit
// CT): it reads 16 samples, so only where `left` samples remain from `r` on.
// False when it did not classify the row (the caller's scalar loop does).
template <typename T>
inline bool AboveRow9(
  const T* r, int count, std::int64_t left, const AboveIsovalue<T>& above, std::uint16_t& bits)
{
#if defined(__SSE2__)
  if constexpr (std::is_same<T, std::uint8_t>::value || std::is_same<T, std::int16_t>::value)
  {
    if (count != BlockCells + 1 || left < 16)
    {
      return false;
    }
    const std::int64_t threshold = above.IntegerThreshold();
    if (threshold <= std::numeric_limits<T>::lowest())
    {
      bits = 0x1FF;
      return true;
    }
    if (threshold > std::numeric_limits<T>::max())
    {
      bits = 0;
      return true;
    }
    int mask;
    if constexpr (std::is_same<T, std::uint8_t>::value)
    {
      // v >= t exactly when max(v, t) == v (unsigned bytes).
      const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r));
      const __m128i t = _mm_set1_epi8(static_cast<char>(threshold));
      mask = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_max_epu8(x, t), x));
    }
    else
    {
      // v >= t exactly when v > t - 1 (t - 1 is a 16-bit value here).
      const __m128i t = _mm_set1_epi16(static_cast<short>(threshold - 1));
      const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r));
      const __m128i hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r + 8));
      mask = _mm_movemask_epi8(_mm_packs_epi16(_mm_cmpgt_epi16(lo, t), _mm_cmpgt_epi16(hi, t)));
    }
    bits = static_cast<std::uint16_t>(mask & 0x1FF);
    return true;
  }
#endif
  (void)r;
  (void)count;
  (void)left;
  (void)above;
  (void)bits;
  return false;
}

// Classifies a block's samples straight from the data (no copy of the values).
template <typename T>
void ClassifyRows(
  const Volume<T>& v, const BlockSamples& s, const AboveIsovalue<T>& above, BlockRows& rows)
{
  const std::int64_t sx = v.Dims[0];
  const std::int64_t sxy = sx * v.Dims[1];
  const std::int64_t readable = sxy * v.Dims[2]; // samples in the volume
  int xs[BlockCells + 1];
  for (int i = 0; i < s.Count[0]; ++i)
  {
    xs[i] = s.Point(0, i);
  }
  for (int k = 0; k < s.Count[2]; ++k)
  {
    const std::int64_t zoff = s.Point(2, k) * sxy;
    for (int j = 0; j < s.Count[1]; ++j)
    {
      const T* row = v.Data + zoff + s.Point(1, j) * sx;
      std::uint32_t a = 0, m = 0;
      if (s.Stride == 1)
      {
        const T* r = row + xs[0];
        if (AboveRow9(r, s.Count[0], readable - (r - v.Data), above, rows.Above[k][j]))
        {
          rows.Missing[k][j] = 0; // integer samples
          continue;
        }
        for (int i = 0; i < s.Count[0]; ++i)
        {
          a |= static_cast<std::uint32_t>(above(r[i])) << i;
          m |= static_cast<std::uint32_t>(IsMissing(r[i])) << i;
        }
      }
      else
      {
        for (int i = 0; i < s.Count[0]; ++i)
        {
          const T value = row[xs[i]];
          a |= static_cast<std::uint32_t>(above(value)) << i;
          m |= static_cast<std::uint32_t>(IsMissing(value)) << i;
        }
      }
      rows.Above[k][j] = static_cast<std::uint16_t>(a & ~m);
      rows.Missing[k][j] = static_cast<std::uint16_t>(m);
    }
  }
}

// Which samples of a block start owned cubes and owned edges, as bit masks
// along each axis (every bit set without ghost cells). Start[a] bit l: the
// cube starting at sample l along a is owned. Around[a] bit l: the cube
// starting at l or at l - 1 is (an edge there is used by an owned cube).
// Sample -1 is the last sample of the block below, whose cubes use the edges
// on this block's lower face (which this block owns).
struct OwnedSamples
{
  std::uint32_t Start[3];
  std::uint32_t Around[3];

  template <typename T>
  OwnedSamples(const Volume<T>& v, const BlockSamples& s)
  {
    const bool ghosts = v.HasGhostCells();
    for (int a = 0; a < 3; ++a)
    {
      this->Start[a] = this->Around[a] = 0xFFFFu;
      if (!ghosts)
      {
        continue;
      }
      this->Start[a] = this->Around[a] = 0;
      bool previous = false; // sample l - 1 starts an owned cube
      for (int l = -1; l < s.Count[a]; ++l)
      {
        const int p = l < 0 ? s.First[a] - s.Stride : s.Point(a, l);
        const bool starts = p >= 0 && p >= v.OwnedCells[2 * a] && p <= v.OwnedCells[2 * a + 1];
        if (l >= 0)
        {
          this->Start[a] |= static_cast<std::uint32_t>(starts) << l;
          this->Around[a] |= static_cast<std::uint32_t>(starts || previous) << l;
        }
        previous = starts;
      }
    }
  }
};

// Pass-1 work on one classified block: the owned cut edges (into `edgeBits`,
// WordsPerBlock words, cleared by the caller) and the cut cubes with their
// cases (into `cutCubes` and `cubeCases` when not null; a cube with a missing
// corner is never cut). Returns the owned cut edges (points: the bits set)
// and the triangles.
struct BlockCounts
{
  std::int64_t Points = 0;
  std::int64_t Triangles = 0;
};

BlockCounts CountBlock(const BlockRows& rows, const BlockSamples& s, const OwnedSamples& owned,
  const TriangleCounts& counts, std::uint64_t* edgeBits, int words, std::uint64_t* cutCubes,
  std::uint8_t* cubeCases)
{
  const int* n = s.Count;
  const int own[3] = { s.Own(0), s.Own(1), s.Own(2) };
  const int L = s.Layout;
  // Samples that start an edge or cube along x, and samples with owned edges along y, z.
  const std::uint32_t startX = ((1u << (n[0] - 1)) - 1) & owned.Start[0];
  const std::uint32_t ownX = ((1u << own[0]) - 1) & owned.Around[0];
  BlockCounts result;
  auto bit = [](std::uint32_t mask, int l) { return (mask >> l) & 1u; };
  for (int k = 0; k < n[2]; ++k)
  {
    for (int j = 0; j < n[1]; ++j)
    {
      const std::uint32_t a = rows.Above[k][j];
      const std::uint32_t m = rows.Missing[k][j];
      const int rowBit = (k * L + j) * L;
      if (j < own[1] && k < own[2] && bit(owned.Around[1], j) && bit(owned.Around[2], k))
      {
        const std::uint32_t cut = (a ^ (a >> 1)) & ~(m | (m >> 1)) & startX;
        if (cut)
        {
          OrBits(edgeBits, rowBit, cut);
        }
      }
      if (j + 1 < n[1] && k < own[2] && bit(owned.Start[1], j) && bit(owned.Around[2], k))
      {
        const std::uint32_t cut =
          (a ^ rows.Above[k][j + 1]) & ~(m | rows.Missing[k][j + 1]) & ownX;
        if (cut)
        {
          OrBits(edgeBits, s.LayoutCube + rowBit, cut);
        }
      }
      if (k + 1 < n[2] && j < own[1] && bit(owned.Around[1], j) && bit(owned.Start[2], k))
      {
        const std::uint32_t cut =
          (a ^ rows.Above[k + 1][j]) & ~(m | rows.Missing[k + 1][j]) & ownX;
        if (cut)
        {
          OrBits(edgeBits, 2 * s.LayoutCube + rowBit, cut);
        }
      }
    }
  }
  for (int k = 0; k + 1 < n[2]; ++k)
  {
    if (!bit(owned.Start[2], k))
    {
      continue;
    }
    for (int j = 0; j + 1 < n[1]; ++j)
    {
      if (!bit(owned.Start[1], j))
      {
        continue;
      }
      const std::uint32_t r00 = rows.Above[k][j], r10 = rows.Above[k][j + 1];
      const std::uint32_t r01 = rows.Above[k + 1][j], r11 = rows.Above[k + 1][j + 1];
      const std::uint32_t any = r00 | r10 | r01 | r11;
      const std::uint32_t all = r00 & r10 & r01 & r11;
      const std::uint32_t missing = rows.Missing[k][j] | rows.Missing[k][j + 1] |
        rows.Missing[k + 1][j] | rows.Missing[k + 1][j + 1];
      std::uint32_t cut =
        (any | (any >> 1)) & ~(all & (all >> 1)) & ~(missing | (missing >> 1)) & startX;
      if (!cut)
      {
        continue;
      }
      // The cases of the row's (up to 8) cubes at once: byte c of `corners`
      // holds corner c of every cube (bit i: cube i); transposed, byte i is
      // cube i's case.
      const std::uint64_t corners = std::uint64_t(r00 & 0xFF) |
        std::uint64_t((r00 >> 1) & 0xFF) << 8 | std::uint64_t((r10 >> 1) & 0xFF) << 16 |
        std::uint64_t(r10 & 0xFF) << 24 | std::uint64_t(r01 & 0xFF) << 32 |
        std::uint64_t((r01 >> 1) & 0xFF) << 40 | std::uint64_t((r11 >> 1) & 0xFF) << 48 |
        std::uint64_t(r11 & 0xFF) << 56;
      const std::uint64_t cubeCasesOfRow = TransposeBits8x8(corners);
      const int rowCube = ((k << s.CubeShift) + j) << s.CubeShift;
      for (; cut; cut &= cut - 1)
      {
        const int i = __builtin_ctz(cut);
        const std::uint32_t c = static_cast<std::uint32_t>(cubeCasesOfRow >> (8 * i)) & 0xFF;
        result.Triangles += counts.Count[c];
        if (cubeCases)
        {
          const int cube = rowCube + i;
          cubeCases[cube] = static_cast<std::uint8_t>(c);
          cutCubes[cube >> 6] |= std::uint64_t(1) << (cube & 63);
        }
      }
    }
  }
  // Points counted per word of the mask, not per row: fewer bit counts.
  for (int w = 0; w < words; ++w)
  {
    result.Points += PopCount64(edgeBits[w]);
  }
  return result;
}

// Negative gradient of the original data at a point, by central differences
// over the level's stride (one-sided on the boundary), in world units. At full
// resolution (stride 1) this is vtkMarchingCubes' gradient divided by the
// spacing; at coarse levels it describes the data as the coarse grid sees it,
// which full-resolution differences at a coarse sample do not (they can point
// anywhere in thin or noisy structures).
template <typename T>
struct GradientOperator
{
  const Volume<T>& V;
  int Stride;
  std::int64_t Step[3];
  int Interior[3];        // full-index distance between the neighbours of an interior sample
  double InvInterior[3];  // 1 / (that distance * spacing): no division in the common case
  int InteriorLast[3];    // last index whose neighbours are both interior-spaced samples

  GradientOperator(const Volume<T>& v, int stride)
    : V(v)
    , Stride(stride)
  {
    this->Step[0] = 1;
    this->Step[1] = v.Dims[0];
    this->Step[2] = static_cast<std::int64_t>(v.Dims[0]) * v.Dims[1];
    for (int a = 0; a < 3; ++a)
    {
      this->Interior[a] = 2 * stride * v.SampleStride;
      this->InvInterior[a] = 1.0 / (this->Interior[a] * v.Spacing[a]);
      // A coarse copy's last sample may sit closer than its stride (the
      // volume's last point off the level's grid): keep it off the fast path.
      this->InteriorLast[a] = v.Dims[a] - 1 - stride - (v.SampleStride > 1 ? 1 : 0);
    }
  }

  void operator()(const int p[3], double g[3]) const
  {
    const std::int64_t at = p[0] + p[1] * this->Step[1] + p[2] * this->Step[2];
    const int s = this->Stride;
    if (p[0] >= s && p[1] >= s && p[2] >= s && p[0] <= this->InteriorLast[0] &&
      p[1] <= this->InteriorLast[1] && p[2] <= this->InteriorLast[2])
    {
      for (int a = 0; a < 3; ++a)
      {
        const std::int64_t d = s * this->Step[a];
        g[a] = (static_cast<double>(this->V.Data[at - d]) -
                 static_cast<double>(this->V.Data[at + d])) *
          this->InvInterior[a];
      }
      return;
    }
    for (int a = 0; a < 3; ++a)
    {
      const int lo = std::max(0, p[a] - this->Stride);
      const int hi = std::min(this->V.Dims[a] - 1, p[a] + this->Stride);
      const double sm = static_cast<double>(this->V.Data[at + (lo - p[a]) * this->Step[a]]);
      const double sp = static_cast<double>(this->V.Data[at + (hi - p[a]) * this->Step[a]]);
      const int distance = this->V.FullIndex(a, hi) - this->V.FullIndex(a, lo);
      g[a] = distance == this->Interior[a] ? (sm - sp) * this->InvInterior[a]
        : distance > 0                     ? (sm - sp) / (distance * this->V.Spacing[a])
                                           : 0.0;
    }
  }
};

} // namespace

void SerialFor(std::int64_t begin, std::int64_t end, const RangeBody& body)
{
  if (begin < end)
  {
    body(begin, end);
  }
}

template <typename T>
Volume<T> MakeCoarseCopy(const Volume<T>& full, int level, std::vector<T>& storage,
  const ParallelFor& parallel)
{
  return MakeStrideCopy(full, LevelStride(level), storage, parallel);
}

template <typename T>
Volume<T> MakeStrideCopy(const Volume<T>& full, int stride, std::vector<T>& storage,
  const ParallelFor& parallel)
{
  Volume<T> coarse = full;
  coarse.SampleStride = stride;
  std::vector<int> points[3];
  for (int a = 0; a < 3; ++a)
  {
    const int n = full.Dims[a];
    const int offset = full.GlobalOffset[a];
    const int whole = full.IsPiece() ? full.GlobalDims[a] : n;
    // First local point on the whole volume's grid of the level, the number
    // of grid points here, and the whole volume's last point when this
    // volume holds it off the grid.
    const int first = (stride - offset % stride) % stride;
    const int onGrid = first <= n - 1 ? (n - 1 - first) / stride + 1 : 0;
    const bool lastOffGrid = offset + n == whole && (onGrid == 0 || (n - 1 - first) % stride != 0);
    coarse.SampleFirst[a] = first;
    coarse.FullDims[a] = n;
    coarse.Dims[a] = onGrid + (lastOffGrid ? 1 : 0);
    points[a].resize(coarse.Dims[a]);
    for (int c = 0; c < coarse.Dims[a]; ++c)
    {
      points[a][c] = std::min(first + c * stride, n - 1);
    }
    // Owned cells: those whose lower sample lies in the full volume's owned range.
    const int lo = full.OwnedCells[2 * a] - first;
    const int hi = full.OwnedCells[2 * a + 1];
    coarse.OwnedCells[2 * a] = lo <= 0 ? 0 : (lo + stride - 1) / stride;
    coarse.OwnedCells[2 * a + 1] =
      hi >= (1 << 29) ? hi : (hi < first ? -1 : (hi - first) / stride);
    if (full.IsPiece())
    {
      coarse.GlobalOffset[a] = (offset + first) / stride;
      coarse.GlobalDims[a] = (whole - 1 + stride - 1) / stride + 1;
    }
  }
  storage.resize(static_cast<std::size_t>(coarse.Dims[0]) * coarse.Dims[1] * coarse.Dims[2]);
  const std::int64_t sx = full.Dims[0];
  const std::int64_t sxy = sx * full.Dims[1];
  parallel(0, coarse.Dims[2], [&](std::int64_t k0, std::int64_t k1) {
    for (std::int64_t k = k0; k < k1; ++k)
    {
      T* out = storage.data() + k * coarse.Dims[0] * static_cast<std::int64_t>(coarse.Dims[1]);
      for (int j = 0; j < coarse.Dims[1]; ++j)
      {
        const T* row = full.Data + points[2][k] * sxy + points[1][j] * sx;
        for (int i = 0; i < coarse.Dims[0]; ++i)
        {
          *out++ = row[points[0][i]];
        }
      }
    }
  });
  coarse.Data = storage.data();
  return coarse;
}

template <typename T>
bool ComputeBlockRange(const Volume<T>& volume, BlockRanges& ranges, std::int64_t block,
  std::int64_t& nans, std::int64_t& infinities)
{
  const std::int64_t b[3] = { block % ranges.Blocks[0],
    (block / ranges.Blocks[0]) % ranges.Blocks[1],
    block / (static_cast<std::int64_t>(ranges.Blocks[0]) * ranges.Blocks[1]) };
  int p0[3], p1[3];
  for (int a = 0; a < 3; ++a)
  {
    p0[a] = static_cast<int>(b[a]) * BlockCells;
    p1[a] = std::min(p0[a] + BlockCells, volume.Dims[a] - 1);
  }
  const std::int64_t sx = volume.Dims[0];
  const std::int64_t sxy = sx * volume.Dims[1];
  T lo = std::numeric_limits<T>::max();
  T hi = std::numeric_limits<T>::lowest();
  for (int z = p0[2]; z <= p1[2]; ++z)
  {
    for (int y = p0[1]; y <= p1[1]; ++y)
    {
      const T* row = volume.Data + z * sxy + y * sx;
      for (int x = p0[0]; x <= p1[0]; ++x)
      {
        const T v = row[x];
        if (IsMissing(v))
        {
          ++(std::isnan(static_cast<double>(v)) ? nans : infinities);
          continue;
        }
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
      }
    }
  }
  if (!(lo <= hi))
  {
    return false;
  }
  ranges.Min[block] = static_cast<double>(lo);
  ranges.Max[block] = static_cast<double>(hi);
  return true;
}

std::int64_t SizeBlockRanges(const int dims[3], BlockRanges& ranges)
{
  for (int a = 0; a < 3; ++a)
  {
    ranges.Dims[a] = dims[a];
    ranges.Blocks[a] = std::max(0, (dims[a] - 1 + BlockCells - 1) / BlockCells);
  }
  const std::int64_t numBlocks = std::max<std::int64_t>(0, ranges.GetNumberOfBlocks());
  ranges.Min.assign(numBlocks, std::numeric_limits<double>::infinity());
  ranges.Max.assign(numBlocks, -std::numeric_limits<double>::infinity());
  ranges.NaNCount = ranges.InfiniteCount = 0;
  ranges.ValueRange[0] = std::numeric_limits<double>::infinity();
  ranges.ValueRange[1] = -std::numeric_limits<double>::infinity();
  return numBlocks;
}

template <typename T>
void ComputeBlockRanges(const Volume<T>& volume, BlockRanges& ranges, const ParallelFor& parallel)
{
  if (SizeBlockRanges(volume.Dims, ranges) <= 0)
  {
    // A piece too thin to hold one cube of a coarse level.
    ranges.ValueRange[0] = ranges.ValueRange[1] = 0;
    return;
  }
  std::vector<std::int64_t> nanPerSlab(ranges.Blocks[2], 0), infPerSlab(ranges.Blocks[2], 0);

  // One z-slab of blocks per task.
  parallel(0, ranges.Blocks[2], [&](std::int64_t bz0, std::int64_t bz1) {
    for (std::int64_t bz = bz0; bz < bz1; ++bz)
    {
      std::int64_t nans = 0, infinities = 0;
      const std::int64_t slab = bz * ranges.Blocks[1] * ranges.Blocks[0];
      for (std::int64_t b = slab; b < slab + ranges.Blocks[1] * ranges.Blocks[0]; ++b)
      {
        ComputeBlockRange(volume, ranges, b, nans, infinities);
      }
      nanPerSlab[bz] = nans;
      infPerSlab[bz] = infinities;
    }
  });
  // Shared faces count missing samples twice; the counts are exact only when 0.
  ranges.NaNCount = ranges.InfiniteCount = 0;
  for (std::size_t bz = 0; bz < nanPerSlab.size(); ++bz)
  {
    ranges.NaNCount += nanPerSlab[bz];
    ranges.InfiniteCount += infPerSlab[bz];
  }
  ranges.ValueRange[0] = *std::min_element(ranges.Min.begin(), ranges.Min.end());
  ranges.ValueRange[1] = *std::max_element(ranges.Max.begin(), ranges.Max.end());
}

double ExtractionPlanBytes(std::int64_t blocks, std::int64_t activeBlocks, int level)
{
  // The vectors PlanExtraction() sizes below, per block and per active block.
  const int cubesPerAxis = BlockCells / LevelStride(level);
  const double perActive = sizeof(std::int32_t) + 2 * sizeof(std::int64_t) +
    cubesPerAxis * cubesPerAxis * cubesPerAxis * sizeof(std::uint8_t) +
    CubeWordsPerBlock(level) * sizeof(std::uint64_t) +
    WordsPerBlock(level) * (sizeof(std::uint64_t) + sizeof(std::uint32_t));
  return static_cast<double>(blocks) * sizeof(std::int32_t) +
    static_cast<double>(activeBlocks) * perActive;
}

namespace
{
// The plan's layout for a level (what every plan of it holds per active block).
void SetPlanLayout(ExtractionPlan& plan, double isovalue, int level)
{
  plan.Isovalue = isovalue;
  plan.Level = level;
  plan.WordsPerBlock = WordsPerBlock(level);
  const int cubesPerAxis = BlockCells / LevelStride(level);
  plan.CubesPerBlock = cubesPerAxis * cubesPerAxis * cubesPerAxis;
  plan.CubeWordsPerBlock = CubeWordsPerBlock(level);
}

// Sizes the per-active-block arrays for `numActive` blocks, those from
// `first` on cleared (cases are read only where a cube's bit is set: not
// cleared).
void ResizePlan(ExtractionPlan& plan, std::int64_t first, std::int64_t numActive)
{
  const int words = plan.WordsPerBlock;
  plan.CubeCases.resize(numActive * plan.CubesPerBlock);
  plan.CutCubes.resize(first * plan.CubeWordsPerBlock);
  plan.CutCubes.resize(numActive * plan.CubeWordsPerBlock, 0);
  plan.EdgeBits.resize(first * words);
  plan.EdgeBits.resize(numActive * words, 0);
  plan.EdgeRank.resize(numActive * words);
  plan.PointOffset.resize(first + 1);
  plan.PointOffset.resize(numActive + 1, 0);
  plan.TriangleOffset.resize(first + 1);
  plan.TriangleOffset.resize(numActive + 1, 0);
}

// Pass 1 on the plan's active blocks [first, numActive): each block's counts
// into PointOffset/TriangleOffset[a + 1], then the running sums from `first`
// on. False (the plan incomplete) when `abort` stopped it.
template <typename T>
bool ClassifyActive(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  ExtractionPlan& plan, std::int64_t first, const ParallelFor& parallel,
  const std::function<bool()>& abort)
{
  const std::int64_t numActive = static_cast<std::int64_t>(plan.ActiveBlocks.size());
  const int words = plan.WordsPerBlock;
  const int stride = LevelStride(plan.Level);
  const TriangleCounts counts(cases);
  const AboveIsovalue<T> above(plan.Isovalue);
  std::atomic<bool> aborted(false);
  parallel(first, numActive, [&](std::int64_t a0, std::int64_t a1) {
    if (aborted || (abort && abort()))
    {
      aborted = true;
      return;
    }
    BlockRows rows;
    for (std::int64_t a = a0; a < a1; ++a)
    {
      const BlockSamples samples(ranges, plan.ActiveBlocks[a], stride);
      ClassifyRows(volume, samples, above, rows);
      std::uint64_t* bits = plan.EdgeBits.data() + a * words;
      const BlockCounts c = CountBlock(rows, samples, OwnedSamples(volume, samples), counts, bits,
        words, plan.CutCubes.data() + a * plan.CubeWordsPerBlock,
        plan.CubeCases.data() + a * plan.CubesPerBlock);
      plan.PointOffset[a + 1] = c.Points;
      plan.TriangleOffset[a + 1] = c.Triangles;
      std::uint32_t* rank = plan.EdgeRank.data() + a * words;
      std::uint32_t before = 0;
      for (int w = 0; w < words; ++w)
      {
        rank[w] = before;
        before += static_cast<std::uint32_t>(PopCount64(bits[w]));
      }
    }
  });
  if (aborted)
  {
    return false;
  }
  for (std::int64_t a = first; a < numActive; ++a)
  {
    plan.PointOffset[a + 1] += plan.PointOffset[a];
    plan.TriangleOffset[a + 1] += plan.TriangleOffset[a];
  }
  return true;
}
} // namespace

template <typename T>
bool PlanExtraction(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  double isovalue, int level, ExtractionPlan& plan, const ParallelFor& parallel,
  const std::function<bool()>& abort)
{
  SetPlanLayout(plan, isovalue, level);
  const std::int64_t numBlocks = ranges.GetNumberOfBlocks();
  plan.ActiveBlocks.clear();
  plan.ActiveIndex.assign(numBlocks, -1);
  for (std::int64_t b = 0; b < numBlocks; ++b)
  {
    if (ranges.IsActive(b, isovalue))
    {
      plan.ActiveIndex[b] = static_cast<std::int32_t>(plan.ActiveBlocks.size());
      plan.ActiveBlocks.push_back(static_cast<std::int32_t>(b));
    }
  }
  ResizePlan(plan, 0, static_cast<std::int64_t>(plan.ActiveBlocks.size()));
  return ClassifyActive(volume, ranges, cases, plan, 0, parallel, abort);
}

void BeginPlan(const BlockRanges& ranges, double isovalue, int level, ExtractionPlan& plan)
{
  SetPlanLayout(plan, isovalue, level);
  plan.ActiveBlocks.clear();
  plan.ActiveIndex.assign(ranges.GetNumberOfBlocks(), -1);
  ResizePlan(plan, 0, 0);
}

template <typename T>
std::int64_t AppendToPlan(const Volume<T>& volume, const BlockRanges& ranges,
  TriangleCaseTable cases, const std::vector<std::int32_t>& blocks, ExtractionPlan& plan,
  const ParallelFor& parallel)
{
  const std::int64_t first = static_cast<std::int64_t>(plan.ActiveBlocks.size());
  for (std::int32_t b : blocks)
  {
    if (plan.ActiveIndex[b] < 0 && ranges.IsActive(b, plan.Isovalue))
    {
      plan.ActiveIndex[b] = static_cast<std::int32_t>(plan.ActiveBlocks.size());
      plan.ActiveBlocks.push_back(b);
    }
  }
  ResizePlan(plan, first, static_cast<std::int64_t>(plan.ActiveBlocks.size()));
  ClassifyActive(volume, ranges, cases, plan, first, parallel, {});
  return first;
}

int PlanOwners(const BlockRanges& ranges, std::int64_t block, std::int64_t owners[7])
{
  const std::int64_t b[3] = { block % ranges.Blocks[0],
    (block / ranges.Blocks[0]) % ranges.Blocks[1],
    block / (static_cast<std::int64_t>(ranges.Blocks[0]) * ranges.Blocks[1]) };
  int n = 0;
  for (int across = 1; across < 8; ++across)
  {
    bool exists = true;
    std::int64_t o[3];
    for (int d = 0; d < 3; ++d)
    {
      const bool along = (across >> d) & 1;
      exists = exists && !(along && b[d] == ranges.Blocks[d] - 1);
      o[d] = b[d] + (along ? 1 : 0);
    }
    if (exists)
    {
      owners[n++] = (o[2] * ranges.Blocks[1] + o[1]) * ranges.Blocks[0] + o[0];
    }
  }
  return n;
}

template <typename T, typename IdType>
void GenerateSurface(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  const ExtractionPlan& plan, const SurfaceBuffers<IdType>& out, const ParallelFor& parallel)
{
  if (out.Ranges)
  {
    *out.Ranges = SurfaceRanges();
  }
  GenerateBlocks(
    volume, ranges, cases, plan, nullptr, GeneratePoints | GenerateTriangles, out, parallel);
}

namespace
{
// normals[3 i + c] = g[c] * (1 / sqrt(len2)) for the n entries (gx, gy, gz,
// len2) of `gradients`, rounded to float. Two entries at a time where SSE2 is
// there: packed square roots and divisions round as scalar ones do, so the
// bits are those of one entry at a time.
void NormaliseGradients(const double* gradients, std::int64_t n, float* normals)
{
  std::int64_t i = 0;
#if defined(__SSE2__)
  const __m128d one = _mm_set1_pd(1.0);
  for (; i + 2 <= n; i += 2)
  {
    const double* g = gradients + 4 * i;
    alignas(16) double inv[2];
    _mm_store_pd(inv, _mm_div_pd(one, _mm_sqrt_pd(_mm_set_pd(g[7], g[3]))));
    for (int p = 0; p < 2; ++p)
    {
      float* nn = normals + 3 * (i + p);
      for (int c = 0; c < 3; ++c)
      {
        nn[c] = static_cast<float>(g[4 * p + c] * inv[p]);
      }
    }
  }
#endif
  for (; i < n; ++i)
  {
    const double* g = gradients + 4 * i;
    const double inv = 1.0 / std::sqrt(g[3]);
    float* nn = normals + 3 * i;
    for (int c = 0; c < 3; ++c)
    {
      nn[c] = static_cast<float>(g[c] * inv);
    }
  }
}
} // namespace

template <typename T, typename IdType>
void GenerateBlocks(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  const ExtractionPlan& plan, const std::vector<std::int64_t>* list, int parts,
  const SurfaceBuffers<IdType>& out, const ParallelFor& parallel)
{
  const int stride = LevelStride(plan.Level);
  const int words = plan.WordsPerBlock;
  const double iso = plan.Isovalue;
  const int layout = LayoutOf(plan.Level);
  const int layoutCube = layout * layout * layout;
  // (i, j, k, axis) of every edge bit, packed 4 bits each: no divisions per point.
  std::vector<std::uint16_t> bitCoords(3 * layoutCube);
  for (int bit = 0; bit < 3 * layoutCube; ++bit)
  {
    const int cell = bit % layoutCube;
    bitCoords[bit] = static_cast<std::uint16_t>((cell % layout) | ((cell / layout) % layout) << 4 |
      (cell / (layout * layout)) << 8 | (bit / layoutCube) << 12);
  }
  // Per set of axes (bit d: axis d), the edge bits whose origin is sample 0
  // along each of those axes: the edges a neighbour across them may own on
  // this block's upper faces.
  std::vector<std::uint64_t> faceMasks(8 * static_cast<std::size_t>(words), 0);
  for (int bit = 0; bit < 3 * layoutCube; ++bit)
  {
    const int l[3] = { bitCoords[bit] & 15, (bitCoords[bit] >> 4) & 15, (bitCoords[bit] >> 8) & 15 };
    for (int across = 1; across < 8; ++across)
    {
      bool onFace = true;
      for (int d = 0; d < 3; ++d)
      {
        onFace = onFace && !(((across >> d) & 1) && l[d] != 0);
      }
      if (onFace)
      {
        faceMasks[across * words + (bit >> 6)] |= std::uint64_t(1) << (bit & 63);
      }
    }
  }
  // Each cube edge's origin (relative to the cube's lower corner), axis, and
  // bit relative to the cube's lower corner's bit.
  int edgeOrigin[12][3];
  int edgeAxis[12];
  int edgeBit[12];
  for (int e = 0; e < 12; ++e)
  {
    for (int c = 0; c < 3; ++c)
    {
      edgeOrigin[e][c] = CornerOffset[EdgeCorners[e][0]][c];
    }
    edgeAxis[e] = EdgeAxis(e);
    edgeBit[e] = edgeAxis[e] * layoutCube + (edgeOrigin[e][2] * layout + edgeOrigin[e][1]) * layout +
      edgeOrigin[e][0];
  }
  // Per case, the bit of each triangle vertex's edge relative to the cube's
  // lower corner's bit, and the number of vertices.
  std::int16_t caseBits[256][15];
  int caseVertices[256];
  for (int c = 0; c < 256; ++c)
  {
    int v = 0;
    for (; v < 15 && cases[c][v] >= 0; ++v)
    {
      caseBits[c][v] = static_cast<std::int16_t>(edgeBit[cases[c][v]]);
    }
    caseVertices[c] = v - v % 3;
  }
  const std::int64_t numActive = list ? static_cast<std::int64_t>(list->size())
                                      : static_cast<std::int64_t>(plan.ActiveBlocks.size());
  const bool writePoints = (parts & GeneratePoints) != 0;
  const bool writeTriangles = (parts & GenerateTriangles) != 0;

  const std::int64_t sx = volume.Dims[0];
  const std::int64_t sxy = sx * volume.Dims[1];
  const std::int64_t step[3] = { 1, sx, sxy };
  const GradientOperator<T> gradient(volume, stride);
  const bool fullVolume = volume.SampleStride == 1;
  auto fullIndex = [&volume, fullVolume](int axis, int c) {
    return fullVolume ? c : volume.FullIndex(axis, c);
  };
  std::mutex rangesMutex;
  parallel(0, numActive, [&](std::int64_t a0, std::int64_t a1) {
    // Point id of each of the block's own cut edges, by bit: filled while the
    // points are written, so most triangle vertices are one load.
    std::vector<IdType> ownIds(static_cast<std::size_t>(words) * 64);
    // The block's unnormalised normals (x, y, z, squared length), normalised
    // after its points: the square roots and divisions then run two at a
    // time, off the point loop's path.
    std::vector<double> gradients(out.Normals ? static_cast<std::size_t>(words) * 64 * 4 : 0);
    SurfaceRanges written; // ranges of this range of blocks, merged at its end
    for (std::int64_t listed = a0; listed < a1; ++listed)
    {
      const std::int64_t a = list ? (*list)[listed] : listed;
      const std::int64_t block = plan.ActiveBlocks[a];
      const BlockSamples s(ranges, block, stride);
      const int* n = s.Count;

      // Points of the owned cut edges, in bit order (values read in place).
      const std::uint64_t* bits = plan.EdgeBits.data() + a * words;
      const std::int64_t firstPid = plan.PointOffset[a];
      std::int64_t pid = firstPid;
      double* gradient4 = gradients.data();
      for (int w = 0; w < words; ++w)
      {
        for (std::uint64_t m = bits[w]; m; m &= m - 1)
        {
          const int bit = w * 64 + __builtin_ctzll(m);
          if (!writePoints)
          {
            // Triangles only: the points were written before, in this order.
            ownIds[bit] = static_cast<IdType>(out.FirstPointId + pid);
            ++pid;
            continue;
          }
          const int packed = bitCoords[bit];
          const int axis = packed >> 12;
          // The edge's ends (an edge never starts at a block's last sample,
          // so its far end is one stride on) and the crossing on it.
          const int p0[3] = { s.First[0] + (packed & 15) * stride,
            s.First[1] + ((packed >> 4) & 15) * stride, s.First[2] + ((packed >> 8) & 15) * stride };
          int p1[3] = { p0[0], p0[1], p0[2] };
          p1[axis] = std::min(p0[axis] + stride, s.Last[axis]);
          const std::int64_t at0 = p0[0] + p0[1] * sx + p0[2] * sxy;
          const double v0 = static_cast<double>(volume.Data[at0]);
          const double v1 = static_cast<double>(volume.Data[at0 + (p1[axis] - p0[axis]) * step[axis]]);
          const double t = (iso - v0) / (v1 - v0);
          float* x = out.Points + 3 * pid;
          for (int c = 0; c < 3; ++c)
          {
            const double f0 = fullIndex(c, p0[c]);
            const double index = c == axis ? f0 + t * (fullIndex(c, p1[c]) - f0) : f0;
            x[c] = static_cast<float>(volume.Origin[c] + volume.Spacing[c] * index);
          }
          if (out.Normals)
          {
            double g0[3], g1[3], g[3];
            gradient(p0, g0);
            gradient(p1, g1);
            double len2 = 0;
            for (int c = 0; c < 3; ++c)
            {
              g[c] = g0[c] + t * (g1[c] - g0[c]);
              len2 += g[c] * g[c];
            }
            if (!(len2 > 0 && len2 < std::numeric_limits<double>::infinity()))
            {
              // Flat gradient, or one read from a missing sample: use the edge
              // itself, pointing to lower values.
              g[0] = g[1] = g[2] = 0;
              g[axis] = v1 > v0 ? -1.0 : 1.0;
              len2 = 1;
            }
            gradient4[0] = g[0];
            gradient4[1] = g[1];
            gradient4[2] = g[2];
            gradient4[3] = len2;
            gradient4 += 4;
          }
          if (out.Ranges)
          {
            written.Points.Add(x);
          }
          if (out.Scalars)
          {
            out.Scalars[pid] = static_cast<float>(iso);
          }
          ownIds[bit] = static_cast<IdType>(out.FirstPointId + pid);
          ++pid;
        }
      }
      if (writePoints && out.Normals)
      {
        NormaliseGradients(gradients.data(), pid - firstPid, out.Normals + 3 * firstPid);
        if (out.Ranges)
        {
          for (std::int64_t q = firstPid; q < pid; ++q)
          {
            written.Normals.Add(out.Normals + 3 * q);
          }
        }
      }
      if (!writeTriangles)
      {
        continue;
      }

      // The ids of the cut edges on the block's upper faces that a neighbour
      // owns (its edges at local sample 0 along each axis it is a neighbour
      // along), written into the free entries of ownIds (no own edge has
      // its origin on an upper face a neighbour owns): then every vertex of
      // every cube is one load, and a neighbour's edge is ranked once, not
      // once per triangle corner.
      const std::int64_t bxyz[3] = { block % ranges.Blocks[0],
        (block / ranges.Blocks[0]) % ranges.Blocks[1],
        block / (static_cast<std::int64_t>(ranges.Blocks[0]) * ranges.Blocks[1]) };
      for (int across = 1; across < 8; ++across)
      {
        bool exists = true;
        std::int64_t owner[3];
        for (int d = 0; d < 3; ++d)
        {
          const bool along = (across >> d) & 1;
          exists = exists && !(along && s.LastBlock[d]);
          owner[d] = bxyz[d] + (along ? 1 : 0);
        }
        if (!exists)
        {
          continue;
        }
        const std::int64_t oa =
          plan.ActiveIndex[(owner[2] * ranges.Blocks[1] + owner[1]) * ranges.Blocks[0] + owner[0]];
        if (oa < 0)
        {
          continue; // no cut edge there
        }
        const std::uint64_t* wordBits = plan.EdgeBits.data() + oa * words;
        const std::uint32_t* wordRank = plan.EdgeRank.data() + oa * words;
        const std::uint64_t* face = faceMasks.data() + across * words;
        const IdType first = static_cast<IdType>(out.FirstPointId + plan.PointOffset[oa]);
        for (int w = 0; w < words; ++w)
        {
          for (std::uint64_t m = wordBits[w] & face[w]; m; m &= m - 1)
          {
            const int bit = w * 64 + __builtin_ctzll(m);
            const std::uint64_t below = wordBits[w] & ((std::uint64_t(1) << (bit & 63)) - 1);
            // The same edge in this block's layout: sample n - 1 instead of 0
            // along each axis the neighbour is across.
            const int packed = bitCoords[bit];
            const int l[3] = { (across & 1) ? n[0] - 1 : (packed & 15),
              (across & 2) ? n[1] - 1 : ((packed >> 4) & 15),
              (across & 4) ? n[2] - 1 : ((packed >> 8) & 15) };
            ownIds[s.Bit(l[0], l[1], l[2], packed >> 12)] =
              first + static_cast<IdType>(wordRank[w] + PopCount64(below));
          }
        }
      }

      // Triangles of every cut cube, every vertex from ownIds.
      std::int64_t tid = plan.TriangleOffset[a];
      const std::uint8_t* cubeCase = plan.CubeCases.data() + a * plan.CubesPerBlock;
      const std::uint64_t* cutCubes = plan.CutCubes.data() + a * plan.CubeWordsPerBlock;
      // Block ids on the whole volume's grid for a piece (extraction runs at
      // stride 1 on the level's volume, so cube (i, j, k) starts at sample
      // First + (i, j, k)); the local block otherwise.
      const bool globalIds = out.BlockIds && volume.IsPiece() && stride == 1;
      std::int64_t globalBlocks[2] = { 0, 0 };
      if (globalIds)
      {
        globalBlocks[0] = (volume.GlobalDims[0] - 1 + BlockCells - 1) / BlockCells;
        globalBlocks[1] = (volume.GlobalDims[1] - 1 + BlockCells - 1) / BlockCells;
      }
      auto blockId = [&](int i, int j, int k) -> std::int32_t {
        if (!globalIds)
        {
          return static_cast<std::int32_t>(block);
        }
        const std::int64_t g[3] = { (volume.GlobalOffset[0] + s.First[0] + i) / BlockCells,
          (volume.GlobalOffset[1] + s.First[1] + j) / BlockCells,
          (volume.GlobalOffset[2] + s.First[2] + k) / BlockCells };
        return static_cast<std::int32_t>((g[2] * globalBlocks[1] + g[1]) * globalBlocks[0] + g[0]);
      };
      const int cubeMask = (1 << s.CubeShift) - 1;
      for (int w = 0; w < plan.CubeWordsPerBlock; ++w)
      {
        for (std::uint64_t m = cutCubes[w]; m; m &= m - 1)
        {
          const int cube = w * 64 + __builtin_ctzll(m);
          const int i = cube & cubeMask;
          const int j = (cube >> s.CubeShift) & cubeMask;
          const int k = cube >> (2 * s.CubeShift);
          const int c = cubeCase[cube];
          const std::int64_t firstTriangle = tid;
          IdType* tri = out.Connectivity + 3 * tid;
          const IdType* ids = ownIds.data() + (k * layout + j) * layout + i;
          const std::int16_t* vertexBits = caseBits[c];
          for (int v = 0; v < caseVertices[c]; v += 3, ++tid, tri += 3)
          {
            tri[0] = ids[vertexBits[v]];
            tri[1] = ids[vertexBits[v + 1]];
            tri[2] = ids[vertexBits[v + 2]];
          }
          if (out.BlockIds)
          {
            std::fill(out.BlockIds + firstTriangle, out.BlockIds + tid, blockId(i, j, k));
          }
        }
      }
    }
    if (out.Ranges && writePoints)
    {
      std::lock_guard<std::mutex> lock(rangesMutex);
      out.Ranges->Points.Merge(written.Points);
      out.Ranges->Normals.Merge(written.Normals);
    }
  });
}

std::vector<std::int32_t> ListActiveBlocks(const BlockRanges& ranges, double isovalue)
{
  std::vector<std::int32_t> active;
  const std::int64_t numBlocks = ranges.GetNumberOfBlocks();
  for (std::int64_t b = 0; b < numBlocks; ++b)
  {
    if (ranges.IsActive(b, isovalue))
    {
      active.push_back(static_cast<std::int32_t>(b));
    }
  }
  return active;
}

template <typename T>
BlockSums CountBlocks(const Volume<T>& volume, const BlockRanges& ranges, TriangleCaseTable cases,
  const std::vector<std::int32_t>& blocks, double isovalue, int level, int auxLevel,
  const ParallelFor& parallel)
{
  const std::int64_t n = static_cast<std::int64_t>(blocks.size());
  // Per block: level points and triangles, auxiliary points and triangles.
  std::vector<std::int64_t> counts(4 * n, 0);
  const TriangleCounts table(cases);
  const AboveIsovalue<T> above(isovalue);
  const int levels[2] = { level, auxLevel };
  parallel(0, n, [&](std::int64_t b0, std::int64_t b1) {
    BlockRows rows;
    std::vector<std::uint64_t> bits(WordsPerBlock(NumberOfLevels - 1));
    for (std::int64_t b = b0; b < b1; ++b)
    {
      for (int which = 0; which < 2 && levels[which] >= 0; ++which)
      {
        const BlockSamples samples(ranges, blocks[b], LevelStride(levels[which]));
        ClassifyRows(volume, samples, above, rows);
        const int words = WordsPerBlock(levels[which]);
        std::fill(bits.begin(), bits.begin() + words, 0);
        const BlockCounts c = CountBlock(rows, samples, OwnedSamples(volume, samples), table,
          bits.data(), words, nullptr, nullptr);
        counts[4 * b + 2 * which] = c.Points;
        counts[4 * b + 2 * which + 1] = c.Triangles;
      }
    }
  });
  BlockSums sums;
  sums.Blocks = n;
  for (std::int64_t b = 0; b < n; ++b)
  {
    const std::int64_t* c = counts.data() + 4 * b;
    const bool auxPoints = auxLevel < 0 || c[2] > 0;
    const bool auxTriangles = auxLevel < 0 || c[3] > 0;
    (auxPoints ? sums.Points : sums.RestPoints) += static_cast<double>(c[0]);
    (auxTriangles ? sums.Triangles : sums.RestTriangles) += static_cast<double>(c[1]);
    sums.AuxPoints += static_cast<double>(c[2]);
    sums.AuxTriangles += static_cast<double>(c[3]);
  }
  return sums;
}

#define MEDISO_INSTANTIATE(T)                                                                      \
  template Volume<T> MakeCoarseCopy<T>(const Volume<T>&, int, std::vector<T>&, const ParallelFor&); \
  template Volume<T> MakeStrideCopy<T>(const Volume<T>&, int, std::vector<T>&, const ParallelFor&); \
  template void ComputeBlockRanges<T>(const Volume<T>&, BlockRanges&, const ParallelFor&);         \
  template bool ComputeBlockRange<T>(                                                              \
    const Volume<T>&, BlockRanges&, std::int64_t, std::int64_t&, std::int64_t&);                   \
  template bool PlanExtraction<T>(const Volume<T>&, const BlockRanges&, TriangleCaseTable, double, \
    int, ExtractionPlan&, const ParallelFor&, const std::function<bool()>&);                       \
  template void GenerateSurface<T, std::int32_t>(const Volume<T>&, const BlockRanges&,            \
    TriangleCaseTable, const ExtractionPlan&, const SurfaceBuffers<std::int32_t>&,                 \
    const ParallelFor&);                                                                           \
  template void GenerateSurface<T, std::int64_t>(const Volume<T>&, const BlockRanges&,            \
    TriangleCaseTable, const ExtractionPlan&, const SurfaceBuffers<std::int64_t>&,                 \
    const ParallelFor&);                                                                           \
  template std::int64_t AppendToPlan<T>(const Volume<T>&, const BlockRanges&, TriangleCaseTable,   \
    const std::vector<std::int32_t>&, ExtractionPlan&, const ParallelFor&);                        \
  template void GenerateBlocks<T, std::int32_t>(const Volume<T>&, const BlockRanges&,             \
    TriangleCaseTable, const ExtractionPlan&, const std::vector<std::int64_t>*, int,              \
    const SurfaceBuffers<std::int32_t>&, const ParallelFor&);                                      \
  template void GenerateBlocks<T, std::int64_t>(const Volume<T>&, const BlockRanges&,             \
    TriangleCaseTable, const ExtractionPlan&, const std::vector<std::int64_t>*, int,              \
    const SurfaceBuffers<std::int64_t>&, const ParallelFor&);                                      \
  template BlockSums CountBlocks<T>(const Volume<T>&, const BlockRanges&, TriangleCaseTable,       \
    const std::vector<std::int32_t>&, double, int, int, const ParallelFor&)

MEDISO_FOR_EACH_SCALAR_TYPE(MEDISO_INSTANTIATE);
#undef MEDISO_INSTANTIATE

} // namespace mediso
