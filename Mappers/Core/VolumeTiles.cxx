// SPDX-License-Identifier: BSD-3-Clause
#include "VolumeTiles.h"

#include <algorithm>
#include <limits>
#include <type_traits>

namespace mediso
{
namespace
{
// Runs body over items [0, items) through `parallel` in tasks of whole items
// of at least `minimum` units (each item `unitsPerItem` units: a slice's
// tiles, a row's points). A host's parallel for may start a thread per task
// (mediso-render's ThreadedFor starts up to one per core at each call), which
// costs more than a small volume's work: a brick's scan or copy, done for
// each of a bricked volume's bricks in turn, then runs as one task.
void ForInTasks(const GLParallelFor& parallel, std::int64_t items, std::size_t unitsPerItem,
  std::size_t minimum, const std::function<void(std::int64_t, std::int64_t)>& body)
{
  const std::int64_t itemsPerTask = std::max<std::int64_t>(1,
    static_cast<std::int64_t>(
      (minimum + unitsPerItem - 1) / std::max<std::size_t>(unitsPerItem, 1)));
  const std::int64_t tasks = (items + itemsPerTask - 1) / itemsPerTask;
  parallel(0, tasks,
    [&](std::int64_t firstTask, std::int64_t endTask)
    { body(firstTask * itemsPerTask, std::min(endTask * itemsPerTask, items)); });
}

// out[2 t] the least and out[2 t + 1] the greatest point value of tile t's
// real cells, as R (every value of T is exact in it).
template<typename T, typename R>
void ComputeTileRanges(const T* data, const int points[3], std::size_t rowValues,
  const PyramidLayout& layout, const GLParallelFor& parallel, std::vector<R>& out)
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
  const std::size_t pointsPerSlice =
    static_cast<std::size_t>(points[0]) * points[1] * static_cast<std::size_t>(factor[2]);
  ForInTasks(parallel, tiles[2], pointsPerSlice, VolumeTiles::MinimumPointsPerTask,
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
            const T* row = data + (static_cast<std::size_t>(z) * points[1] + y) * rowValues;
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

// What an empty tile holds: least above greatest, which no threshold lies between.
template <typename R>
R EmptyLow()
{
  return std::numeric_limits<R>::has_infinity ? std::numeric_limits<R>::infinity()
                                              : std::numeric_limits<R>::max();
}
template <typename R>
R EmptyHigh()
{
  return std::numeric_limits<R>::has_infinity ? -std::numeric_limits<R>::infinity()
                                              : std::numeric_limits<R>::lowest();
}

// The ranges of the tiles whose points meet [first, last], each from its own points where they
// have all arrived, else empty (ComputeTileRanges' tiles: cells [t span, (t + 1) span) along an
// axis, cut to the volume, and their points one further).
template <typename T, typename R>
void ComputeRegionRanges(const T* data, const int points[3], const PyramidLayout& layout,
  const int first[3], const int last[3], const PointsArrived& arrived, std::vector<R>& out)
{
  const auto tiles = layout.TileCounts();
  const auto factor = layout.Factor(1);
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  const int span[3] = { 2 * PyramidLayout::TileTexels * factor[0],
    2 * PyramidLayout::TileTexels * factor[1], factor[2] };
  const int count[3] = { tiles[0], tiles[1], tiles[2] };
  int t0[3], t1[3];
  for (int a = 0; a < 3; ++a)
  {
    // Tile t holds points [t span, (t + 1) span]: a point on a boundary is in two tiles.
    t0[a] = std::max(0, std::max(0, first[a]) - 1) / span[a];
    t1[a] = std::min(count[a] - 1, std::min(last[a], cells[a]) / span[a]);
  }
  for (int tz = t0[2]; tz <= t1[2]; ++tz)
  {
    for (int ty = t0[1]; ty <= t1[1]; ++ty)
    {
      for (int tx = t0[0]; tx <= t1[0]; ++tx)
      {
        const int t[3] = { tx, ty, tz };
        int lo[3], hi[3];
        bool real = true;
        for (int a = 0; a < 3; ++a)
        {
          lo[a] = t[a] * span[a];
          hi[a] = std::min(lo[a] + span[a], cells[a]);
          real = real && lo[a] < cells[a];
        }
        R low = EmptyLow<R>(), high = EmptyHigh<R>();
        if (real && arrived(lo, hi))
        {
          for (int z = lo[2]; z <= hi[2]; ++z)
          {
            for (int y = lo[1]; y <= hi[1]; ++y)
            {
              const T* row = data + (static_cast<std::size_t>(z) * points[1] + y) * points[0];
              for (int x = lo[0]; x <= hi[0]; ++x)
              {
                const R v = static_cast<R>(row[x]);
                low = v < low ? v : low; // NaN compares false: left out
                high = v > high ? v : high;
              }
            }
          }
        }
        const std::size_t index =
          (static_cast<std::size_t>(tz) * count[1] + ty) * count[0] + static_cast<std::size_t>(tx);
        out[2 * index] = low;
        out[2 * index + 1] = high;
      }
    }
  }
}

void SerialFor(
  std::int64_t begin, std::int64_t end, const std::function<void(std::int64_t, std::int64_t)>& body)
{
  if (begin < end)
  {
    body(begin, end);
  }
}
} // namespace

//------------------------------------------------------------------------------
GLParallelFor SerialIfEmpty(const GLParallelFor& parallel)
{
  return parallel ? parallel : GLParallelFor(SerialFor);
}

int PackedVolumeWidth(int pointsX)
{
  return (pointsX + 3) / 4;
}

std::vector<unsigned char> PackVolumeRows(
  const void* data, const int points[3], int bytesPerValue, const GLParallelFor& parallel)
{
  const int whole[6] = { 0, points[0] - 1, 0, points[1] - 1, 0, points[2] - 1 };
  std::vector<unsigned char> packed;
  PackVolumeBox(data, points, whole, bytesPerValue, parallel, packed);
  return packed;
}

void PackVolumeBox(const void* volume, const int volumePoints[3], const int extent[6],
  int bytesPerValue, const GLParallelFor& parallel, std::vector<unsigned char>& packed)
{
  const int points[3] = { extent[1] - extent[0] + 1, extent[3] - extent[2] + 1,
    extent[5] - extent[4] + 1 };
  const std::size_t inRow = static_cast<std::size_t>(points[0]) * bytesPerValue;
  const std::size_t outRow =
    static_cast<std::size_t>(4 * PackedVolumeWidth(points[0])) * bytesPerValue;
  const std::int64_t rows = static_cast<std::int64_t>(points[1]) * points[2];
  packed.resize(outRow * static_cast<std::size_t>(rows));
  const unsigned char* in = static_cast<const unsigned char*>(volume);
  ForInTasks(SerialIfEmpty(parallel), rows, static_cast<std::size_t>(points[0]),
    VolumeTiles::MinimumPointsPerTask,
    [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t r = begin; r < end; ++r)
      {
        // Row r of the box: its y and z in the volume.
        const std::int64_t y = extent[2] + r % points[1];
        const std::int64_t z = extent[4] + r / points[1];
        const unsigned char* from = in +
          ((z * volumePoints[1] + y) * volumePoints[0] + extent[0]) *
            static_cast<std::int64_t>(bytesPerValue);
        unsigned char* to = packed.data() + outRow * r;
        std::copy(from, from + inRow, to);
        for (std::size_t pad = inRow; pad < outRow; pad += bytesPerValue)
        {
          std::copy(from + inRow - bytesPerValue, from + inRow, to + pad);
        }
      }
    });
}

//------------------------------------------------------------------------------
void VolumeTiles::Compute(ScalarType type, const void* data, const int points[3],
  const PyramidLayout& layout, const GLParallelFor& parallel)
{
  this->Compute(type, data, points, points[0], layout, parallel);
}

void VolumeTiles::Compute(ScalarType type, const void* data, const int points[3], int rowValues,
  const PyramidLayout& layout, const GLParallelFor& parallel)
{
  this->Clear();
  const std::size_t row = static_cast<std::size_t>(std::max(rowValues, points[0]));
  const GLParallelFor run = SerialIfEmpty(parallel);
  const ScalarType rangeType = type == ScalarType::Float64 ? ScalarType::Float32 : type;
  VisitScalarType(rangeType,
    [&](auto tag)
    {
      using T = decltype(tag);
      const T* typed = static_cast<const T*>(data);
      switch (ValueKindOf(type))
      {
        case ValueKind::Signed:
          ComputeTileRanges(typed, points, row, layout, run, this->IntRanges);
          break;
        case ValueKind::Unsigned:
          ComputeTileRanges(typed, points, row, layout, run, this->UIntRanges);
          break;
        case ValueKind::Float:
          ComputeTileRanges(typed, points, row, layout, run, this->FloatRanges);
          break;
      }
    });
  this->Layout = layout;
}

void VolumeTiles::ComputeRegion(ScalarType type, const void* data, const int points[3],
  const int first[3], const int last[3], const PointsArrived& arrived)
{
  if (this->GetNumberOfTiles() == 0)
  {
    return; // no layout: Compute() or Reset() first
  }
  // Values of their own type: double ones become the float they are on the GPU, one by one.
  VisitScalarType(type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const T* typed = static_cast<const T*>(data);
      switch (ValueKindOf(type))
      {
        case ValueKind::Signed:
          ComputeRegionRanges(typed, points, this->Layout, first, last, arrived, this->IntRanges);
          break;
        case ValueKind::Unsigned:
          ComputeRegionRanges(typed, points, this->Layout, first, last, arrived, this->UIntRanges);
          break;
        case ValueKind::Float:
          ComputeRegionRanges(typed, points, this->Layout, first, last, arrived, this->FloatRanges);
          break;
      }
    });
}

void VolumeTiles::Clear()
{
  this->Layout = PyramidLayout();
  this->IntRanges.clear();
  this->UIntRanges.clear();
  this->FloatRanges.clear();
}

namespace
{

template<typename R>
void EmptyRanges(std::vector<R>& ranges, std::size_t tiles)
{
  ranges.resize(2 * tiles);
  for (std::size_t t = 0; t < tiles; ++t)
  {
    ranges[2 * t] = EmptyLow<R>();
    ranges[2 * t + 1] = EmptyHigh<R>();
  }
}

// Tiles [origin, origin + count) of `to` (tile counts `toTiles`) from `from`
// (tile counts `fromTiles`; empty where it has none).
template<typename R>
void PlaceRanges(std::vector<R>& to, const PyramidLayout::Int3& toTiles, const std::vector<R>* from,
  const PyramidLayout::Int3& fromTiles, const int origin[3], const int count[3])
{
  for (int z = 0; z < count[2] && origin[2] + z < toTiles[2]; ++z)
    for (int y = 0; y < count[1] && origin[1] + y < toTiles[1]; ++y)
      for (int x = 0; x < count[0] && origin[0] + x < toTiles[0]; ++x)
      {
        const std::size_t t =
          (static_cast<std::size_t>(origin[2] + z) * toTiles[1] + origin[1] + y) * toTiles[0] +
          origin[0] + x;
        const bool inside = from && x < fromTiles[0] && y < fromTiles[1] && z < fromTiles[2];
        const std::size_t f =
          inside ? (static_cast<std::size_t>(z) * fromTiles[1] + y) * fromTiles[0] + x : 0;
        to[2 * t] = inside ? (*from)[2 * f] : EmptyLow<R>();
        to[2 * t + 1] = inside ? (*from)[2 * f + 1] : EmptyHigh<R>();
      }
}
} // namespace

void VolumeTiles::Reset(ScalarType type, const PyramidLayout& layout)
{
  this->Clear();
  this->Layout = layout;
  const auto tiles = layout.TileCounts();
  const std::size_t n = static_cast<std::size_t>(tiles[0]) * tiles[1] * tiles[2];
  switch (ValueKindOf(type))
  {
    case ValueKind::Signed:
      EmptyRanges(this->IntRanges, n);
      break;
    case ValueKind::Unsigned:
      EmptyRanges(this->UIntRanges, n);
      break;
    case ValueKind::Float:
      EmptyRanges(this->FloatRanges, n);
      break;
  }
}

void VolumeTiles::Place(const VolumeTiles* part, const int origin[3], const int count[3])
{
  const auto tiles = this->Layout.TileCounts();
  const auto partTiles = part ? part->Layout.TileCounts() : PyramidLayout::Int3{ { 0, 0, 0 } };
  if (!this->IntRanges.empty())
  {
    PlaceRanges(
      this->IntRanges, tiles, part ? &part->IntRanges : nullptr, partTiles, origin, count);
  }
  if (!this->UIntRanges.empty())
  {
    PlaceRanges(
      this->UIntRanges, tiles, part ? &part->UIntRanges : nullptr, partTiles, origin, count);
  }
  if (!this->FloatRanges.empty())
  {
    PlaceRanges(
      this->FloatRanges, tiles, part ? &part->FloatRanges : nullptr, partTiles, origin, count);
  }
}

std::uint64_t VolumeTiles::GetNumberOfTiles() const
{
  return (this->IntRanges.size() + this->UIntRanges.size() + this->FloatRanges.size()) / 2;
}

bool VolumeTiles::IsActive(const IsoThresholds& thresholds, std::size_t t) const
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
}

std::vector<std::uint16_t> VolumeTiles::ActiveRectangles(
  const IsoThresholds& thresholds, const GLParallelFor& parallel, std::uint64_t& tilesDrawn) const
{
  const PyramidLayout& layout = this->Layout;
  const auto tiles = layout.TileCounts();
  const auto packed = layout.Packed(1);
  const std::size_t perSlice = static_cast<std::size_t>(tiles[0]) * tiles[1];
  // Per slice, in tasks of whole slices of at least MinimumTilesPerTask tiles
  // (a brick's scan at each isovalue change is one task); then joined in
  // slice order.
  std::vector<std::vector<std::uint16_t>> slices(static_cast<std::size_t>(tiles[2]));
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(tiles[2]), 0);
  ForInTasks(SerialIfEmpty(parallel), tiles[2], perSlice, MinimumTilesPerTask,
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
            if (!this->IsActive(thresholds, t + tx))
            {
              ++tx;
              continue;
            }
            int end = tx + 1;
            while (end < tiles[0] && this->IsActive(thresholds, t + end))
            {
              ++end;
            }
            counts[z] += static_cast<std::uint64_t>(end - tx);
            const auto lo = layout.AtlasTexel(1, tx * PyramidLayout::TileTexels,
              ty * PyramidLayout::TileTexels, static_cast<int>(z));
            const int w =
              std::min(end * PyramidLayout::TileTexels, packed[0]) - tx * PyramidLayout::TileTexels;
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

} // namespace mediso
