// SPDX-License-Identifier: BSD-3-Clause
#include "BrickGrid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>

namespace mediso
{
namespace
{
bool ExtentInside(const int extent[6], const int points[3])
{
  for (int a = 0; a < 3; ++a)
  {
    if (extent[2 * a] < 0 || extent[2 * a] > extent[2 * a + 1] || extent[2 * a + 1] >= points[a])
    {
      return false;
    }
  }
  return true;
}

bool ExtentContains(const int outer[6], const int inner[6])
{
  for (int a = 0; a < 3; ++a)
  {
    if (inner[2 * a] < outer[2 * a] || inner[2 * a + 1] > outer[2 * a + 1])
    {
      return false;
    }
  }
  return true;
}

// Copies the rows of `region` (inclusive, inside both) from a box laid out
// over `from` to a box laid out over `to`, both x fastest.
void CopyRegion(const int region[6], const int from[6], const unsigned char* source,
  const int to[6], unsigned char* target, int bytesPerValue)
{
  const std::int64_t fromX = from[1] - from[0] + 1;
  const std::int64_t fromY = from[3] - from[2] + 1;
  const std::int64_t toX = to[1] - to[0] + 1;
  const std::int64_t toY = to[3] - to[2] + 1;
  const std::size_t rowBytes = static_cast<std::size_t>(region[1] - region[0] + 1) * bytesPerValue;
  for (int z = region[4]; z <= region[5]; ++z)
  {
    for (int y = region[2]; y <= region[3]; ++y)
    {
      const std::int64_t a =
        ((z - from[4]) * fromY + (y - from[2])) * fromX + (region[0] - from[0]);
      const std::int64_t b = ((z - to[4]) * toY + (y - to[2])) * toX + (region[0] - to[0]);
      std::memcpy(target + b * bytesPerValue, source + a * bytesPerValue, rowBytes);
    }
  }
}

template<typename T>
BrickRange ExtentRange(const T* data, const int points[3], const int extent[6])
{
  double low = std::numeric_limits<double>::infinity();
  double high = -std::numeric_limits<double>::infinity();
  // Per row in T, then as double. The row's bounds start past every value
  // (infinities for floats, the type's ends for integers) so that the loop
  // has no branch and vectorises: a NaN compares false and is left out, and
  // a row of NaN values only keeps low > high, which adds nothing.
  const T rowStartLow = std::numeric_limits<T>::has_infinity ? std::numeric_limits<T>::infinity()
                                                             : std::numeric_limits<T>::max();
  const T rowStartHigh = std::numeric_limits<T>::has_infinity ? -std::numeric_limits<T>::infinity()
                                                              : std::numeric_limits<T>::lowest();
  for (int z = extent[4]; z <= extent[5]; ++z)
  {
    for (int y = extent[2]; y <= extent[3]; ++y)
    {
      const T* row = data + (static_cast<std::int64_t>(z) * points[1] + y) * points[0];
      T rowLow = rowStartLow, rowHigh = rowStartHigh;
      for (int x = extent[0]; x <= extent[1]; ++x)
      {
        const T v = row[x];
        rowLow = v < rowLow ? v : rowLow;
        rowHigh = v > rowHigh ? v : rowHigh;
      }
      if (rowLow <= rowHigh)
      {
        low = std::min(low, static_cast<double>(rowLow));
        high = std::max(high, static_cast<double>(rowHigh));
      }
    }
  }
  return BrickRange{ low, high };
}
} // namespace

BrickGrid::BrickGrid(const int points[3], int brickPoints)
{
  if (brickPoints <= 0 || brickPoints % BlockCells != 0)
  {
    return;
  }
  for (int a = 0; a < 3; ++a)
  {
    if (points[a] < 1)
    {
      return;
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    this->Points[a] = points[a];
    this->Bricks[a] =
      static_cast<int>((static_cast<std::int64_t>(points[a]) + brickPoints - 1) / brickPoints);
  }
  this->BrickPoints = brickPoints;
}

std::int64_t BrickGrid::GetNumberOfBricks() const
{
  return static_cast<std::int64_t>(this->Bricks[0]) * this->Bricks[1] * this->Bricks[2];
}

std::int64_t BrickGrid::BrickId(int bx, int by, int bz) const
{
  return bx +
    static_cast<std::int64_t>(this->Bricks[0]) *
    (by + static_cast<std::int64_t>(this->Bricks[1]) * bz);
}

void BrickGrid::BrickIndex(std::int64_t brick, int index[3]) const
{
  const std::int64_t nx = std::max(this->Bricks[0], 1);
  const std::int64_t ny = std::max(this->Bricks[1], 1);
  index[0] = static_cast<int>(brick % nx);
  index[1] = static_cast<int>((brick / nx) % ny);
  index[2] = static_cast<int>(brick / (nx * ny));
}

void BrickGrid::OwnedPoints(std::int64_t brick, int extent[6]) const
{
  if (brick < 0 || brick >= this->GetNumberOfBricks())
  {
    const int empty[6] = { 0, -1, 0, -1, 0, -1 };
    std::copy(empty, empty + 6, extent);
    return;
  }
  int index[3];
  this->BrickIndex(brick, index);
  for (int a = 0; a < 3; ++a)
  {
    const std::int64_t first = static_cast<std::int64_t>(index[a]) * this->BrickPoints;
    extent[2 * a] = static_cast<int>(first);
    extent[2 * a + 1] =
      static_cast<int>(std::min<std::int64_t>(first + this->BrickPoints, this->Points[a]) - 1);
  }
}

void BrickGrid::ReadPoints(std::int64_t brick, int apron, int extent[6]) const
{
  this->OwnedPoints(brick, extent);
  if (extent[0] > extent[1])
  {
    return;
  }
  apron = std::max(apron, 0);
  for (int a = 0; a < 3; ++a)
  {
    extent[2 * a] = std::max(extent[2 * a] - apron, 0);
    extent[2 * a + 1] = static_cast<int>(std::min<std::int64_t>(
      static_cast<std::int64_t>(extent[2 * a + 1]) + 1 + apron, this->Points[a] - 1));
  }
}

std::vector<std::int64_t> BrickGrid::BricksTouching(const int extent[6]) const
{
  std::vector<std::int64_t> bricks;
  if (!this->IsValid())
  {
    return bricks;
  }
  int first[3], last[3];
  for (int a = 0; a < 3; ++a)
  {
    const int lo = std::max(extent[2 * a], 0);
    const int hi = std::min(extent[2 * a + 1], this->Points[a] - 1);
    if (lo > hi)
    {
      return bricks;
    }
    first[a] = lo / this->BrickPoints;
    last[a] = hi / this->BrickPoints;
  }
  for (int z = first[2]; z <= last[2]; ++z)
  {
    for (int y = first[1]; y <= last[1]; ++y)
    {
      for (int x = first[0]; x <= last[0]; ++x)
      {
        bricks.push_back(this->BrickId(x, y, z));
      }
    }
  }
  return bricks;
}

std::uint64_t BrickGrid::ExtentPoints(const int extent[6])
{
  std::uint64_t count = 1;
  for (int a = 0; a < 3; ++a)
  {
    if (extent[2 * a] > extent[2 * a + 1])
    {
      return 0;
    }
    count *= static_cast<std::uint64_t>(extent[2 * a + 1] - extent[2 * a] + 1);
  }
  return count;
}

std::uint64_t BrickGrid::OwnedBytes(std::int64_t brick, int bytesPerValue) const
{
  int extent[6];
  this->OwnedPoints(brick, extent);
  return ExtentPoints(extent) * static_cast<std::uint64_t>(std::max(bytesPerValue, 0));
}

std::vector<BrickRange> ComputeBrickRanges(
  const BrickGrid& grid, ScalarType type, const void* data, int apron, const ParallelFor& parallel)
{
  std::vector<BrickRange> ranges;
  if (!grid.IsValid() || !data)
  {
    return ranges;
  }
  ranges.resize(static_cast<std::size_t>(grid.GetNumberOfBricks()));
  const ParallelFor run = parallel ? parallel : ParallelFor(SerialFor);
  VisitScalarType(type,
    [&](auto zero)
    {
      using T = decltype(zero);
      const T* values = static_cast<const T*>(data);
      run(0, grid.GetNumberOfBricks(),
        [&](std::int64_t begin, std::int64_t end)
        {
          for (std::int64_t brick = begin; brick < end; ++brick)
          {
            int extent[6];
            grid.ReadPoints(brick, apron, extent);
            ranges[brick] = ExtentRange(values, grid.GetPoints(), extent);
          }
        });
    });
  return ranges;
}

bool BrickCrosses(const BrickRange& range, const std::vector<double>& isovalues)
{
  for (const double iso : isovalues)
  {
    if (range.Min < iso && iso <= range.Max)
    {
      return true;
    }
  }
  return false;
}

std::vector<std::int64_t> ActiveBricks(
  const std::vector<BrickRange>& ranges, const std::vector<double>& isovalues)
{
  std::vector<std::int64_t> active;
  for (std::size_t b = 0; b < ranges.size(); ++b)
  {
    if (BrickCrosses(ranges[b], isovalues))
    {
      active.push_back(static_cast<std::int64_t>(b));
    }
  }
  return active;
}

bool CopyBrick(const BrickGrid& grid, std::int64_t brick, const int extent[6], const void* volume,
  int bytesPerValue, void* out)
{
  if (brick < 0 || brick >= grid.GetNumberOfBricks() || bytesPerValue <= 0 || !volume || !out ||
    !ExtentInside(extent, grid.GetPoints()))
  {
    return false;
  }
  const int* n = grid.GetPoints();
  const int whole[6] = { 0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1 };
  CopyRegion(extent, whole, static_cast<const unsigned char*>(volume), extent,
    static_cast<unsigned char*>(out), bytesPerValue);
  return true;
}

bool WriteBrick(const BrickGrid& grid, std::int64_t brick, const int extent[6], int bytesPerValue,
  const void* brickValues, void* volume)
{
  int owned[6];
  grid.OwnedPoints(brick, owned);
  if (owned[0] > owned[1] || bytesPerValue <= 0 || !brickValues || !volume ||
    !ExtentInside(extent, grid.GetPoints()) || !ExtentContains(extent, owned))
  {
    return false;
  }
  const int* n = grid.GetPoints();
  const int whole[6] = { 0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1 };
  CopyRegion(owned, extent, static_cast<const unsigned char*>(brickValues), whole,
    static_cast<unsigned char*>(volume), bytesPerValue);
  return true;
}

bool BrickResidency::IsResident(std::int64_t brick) const
{
  return this->Where.count(brick) != 0;
}

void BrickResidency::Touch(std::int64_t brick)
{
  const auto found = this->Where.find(brick);
  if (found != this->Where.end())
  {
    this->Order.splice(this->Order.end(), this->Order, found->second);
  }
}

bool BrickResidency::MakeResident(
  std::int64_t brick, std::uint64_t bytes, std::vector<std::int64_t>& evicted)
{
  if (bytes > this->Budget)
  {
    return false;
  }
  // A resident brick is first taken out, so that it is not its own victim.
  const auto found = this->Where.find(brick);
  if (found != this->Where.end())
  {
    this->ResidentBytes -= found->second->Bytes;
    this->Order.erase(found->second);
    this->Where.erase(found);
  }
  while (this->ResidentBytes + bytes > this->Budget && !this->Order.empty())
  {
    const Entry oldest = this->Order.front();
    this->Order.pop_front();
    this->Where.erase(oldest.Brick);
    this->ResidentBytes -= oldest.Bytes;
    evicted.push_back(oldest.Brick);
  }
  this->Order.push_back(Entry{ brick, bytes });
  this->Where[brick] = std::prev(this->Order.end());
  this->ResidentBytes += bytes;
  return true;
}

bool BrickResidency::Evict(std::int64_t brick)
{
  const auto found = this->Where.find(brick);
  if (found == this->Where.end())
  {
    return false;
  }
  this->ResidentBytes -= found->second->Bytes;
  this->Order.erase(found->second);
  this->Where.erase(found);
  return true;
}

void BrickResidency::Clear()
{
  this->Order.clear();
  this->Where.clear();
  this->ResidentBytes = 0;
}

std::vector<std::int64_t> BrickResidency::GetResidentBricks() const
{
  std::vector<std::int64_t> bricks;
  bricks.reserve(this->Order.size());
  for (const Entry& entry : this->Order)
  {
    bricks.push_back(entry.Brick);
  }
  return bricks;
}

} // namespace mediso
