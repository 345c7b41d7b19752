// SPDX-License-Identifier: BSD-3-Clause
#include "PyramidLayout.h"

#include <algorithm>

namespace mediso
{
namespace
{
int NextPowerOfTwo(int n)
{
  int p = 1;
  while (p < n)
  {
    p *= 2;
  }
  return p;
}
} // namespace

PyramidLayout::PyramidLayout(const int cells[3])
{
  Int3 size;
  for (int a = 0; a < 3; ++a)
  {
    this->Cells[a] = std::max(1, cells[a]);
    size[a] = NextPowerOfTwo(this->Cells[a]);
  }
  const Int3 base = size;
  this->Sizes.push_back(size);
  this->Columns.push_back(0);
  this->Bytes.push_back(0);
  do
  {
    for (int& s : size)
    {
      s = s > 1 ? s / 2 : 1;
    }
    this->Sizes.push_back(size);
    // The largest count of a node: every isovalue crossing every cell under it.
    const double maxCount = static_cast<double>(MaximumIsovalues) * (base[0] / size[0]) *
      (base[1] / size[1]) * (base[2] / size[2]);
    this->Bytes.push_back(maxCount <= 255.0 ? 1 : (maxCount <= 65535.0 ? 2 : 4));
    // Atlas columns: the power of two that makes the atlas closest to square
    // (the smaller width on a tie).
    const Int3 packed = this->Packed(this->GetNumberOfLevels() - 1);
    int best = 1;
    long long bestSide = -1;
    for (int c = 1; c <= packed[2]; c *= 2)
    {
      const long long side =
        std::max(static_cast<long long>(packed[0]) * c, static_cast<long long>(packed[1]) * (packed[2] / c));
      if (bestSide < 0 || side < bestSide)
      {
        best = c;
        bestSide = side;
      }
    }
    this->Columns.push_back(best);
  } while (size[0] > 1 || size[1] > 1 || size[2] > 1);
}

PyramidLayout::Int3 PyramidLayout::Factor(int level) const
{
  const Int3& lower = this->Sizes[level - 1];
  const Int3& size = this->Sizes[level];
  return { lower[0] / size[0], lower[1] / size[1], lower[2] / size[2] };
}

PyramidLayout::Int3 PyramidLayout::CellsPerNode(int level) const
{
  const Int3& base = this->Sizes[0];
  const Int3& size = this->Sizes[level];
  return { base[0] / size[0], base[1] / size[1], base[2] / size[2] };
}

PyramidLayout::Int3 PyramidLayout::Packed(int level) const
{
  const Int3& size = this->Sizes[level];
  return { std::max(1, size[0] / 2), std::max(1, size[1] / 2), size[2] };
}

std::array<int, 2> PyramidLayout::AtlasSize(int level) const
{
  const Int3 packed = this->Packed(level);
  const int columns = this->Columns[level];
  return { packed[0] * columns, packed[1] * (packed[2] / columns) };
}

std::array<int, 2> PyramidLayout::AtlasTexel(int level, int x, int y, int z) const
{
  const Int3 packed = this->Packed(level);
  const int columns = this->Columns[level];
  return { x + (z % columns) * packed[0], y + (z / columns) * packed[1] };
}

std::uint64_t PyramidLayout::GetStoredBytes() const
{
  std::uint64_t bytes = 0;
  for (int l = 1; l < this->GetNumberOfLevels(); ++l)
  {
    const Int3 packed = this->Packed(l);
    bytes += static_cast<std::uint64_t>(packed[0]) * packed[1] * packed[2] * 4 * this->Bytes[l];
  }
  return bytes;
}

PyramidLayout::Int3 PyramidLayout::TileCounts() const
{
  if (this->GetNumberOfLevels() < 2)
  {
    return { 0, 0, 0 };
  }
  const Int3 packed = this->Packed(1);
  return { (packed[0] + TileTexels - 1) / TileTexels, (packed[1] + TileTexels - 1) / TileTexels,
    packed[2] };
}

} // namespace mediso
