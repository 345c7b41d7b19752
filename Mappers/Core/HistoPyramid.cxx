// SPDX-License-Identifier: BSD-3-Clause
#include "HistoPyramid.h"

#include "ScalarTypes.h"

#include <algorithm>
#include <cmath>

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

void HistoPyramid::Build(const int cells[3], const std::vector<std::uint32_t>& baseCounts)
{
  this->Levels.clear();
  Level base;
  for (int a = 0; a < 3; ++a)
  {
    this->Cells[a] = std::max(1, cells[a]);
    base.Size[a] = NextPowerOfTwo(this->Cells[a]);
  }
  base.Counts.assign(static_cast<std::size_t>(base.Size[0]) * base.Size[1] * base.Size[2], 0);
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i)
        base.Counts[(static_cast<std::size_t>(k) * base.Size[1] + j) * base.Size[0] + i] =
          baseCounts[(static_cast<std::size_t>(k) * cells[1] + j) * cells[0] + i];
  this->Levels.push_back(std::move(base));

  // Each level halves every axis larger than 1 and sums the children: the
  // reduction the GPU does in one render-to-texture pass per output slice.
  while (true)
  {
    const Level& below = this->Levels.back();
    // A single cell still gets a level 1 (as on the GPU, which never stores
    // level 0 and so always needs one level above it).
    if (below.Size[0] == 1 && below.Size[1] == 1 && below.Size[2] == 1 && this->Levels.size() > 1)
    {
      break;
    }
    Level up;
    int factor[3];
    for (int a = 0; a < 3; ++a)
    {
      factor[a] = below.Size[a] > 1 ? 2 : 1;
      up.Size[a] = below.Size[a] / factor[a];
    }
    up.Counts.assign(static_cast<std::size_t>(up.Size[0]) * up.Size[1] * up.Size[2], 0);
    for (int k = 0; k < up.Size[2]; ++k)
      for (int j = 0; j < up.Size[1]; ++j)
        for (int i = 0; i < up.Size[0]; ++i)
        {
          std::uint32_t sum = 0;
          for (int c = 0; c < 8; ++c)
          {
            const int d[3] = { c & 1, (c >> 1) & 1, (c >> 2) & 1 };
            if (d[0] >= factor[0] || d[1] >= factor[1] || d[2] >= factor[2])
            {
              continue;
            }
            const int x = i * factor[0] + d[0], y = j * factor[1] + d[1], z = k * factor[2] + d[2];
            sum += below.Counts[(static_cast<std::size_t>(z) * below.Size[1] + y) * below.Size[0] + x];
          }
          up.Counts[(static_cast<std::size_t>(k) * up.Size[1] + j) * up.Size[0] + i] = sum;
        }
    this->Levels.push_back(std::move(up));
  }
}

template <typename T>
std::vector<std::uint32_t> HistoPyramid::CountCrossings(
  const T* data, const int points[3], const std::vector<double>& isovalues)
{
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  std::vector<std::uint32_t> counts(
    static_cast<std::size_t>(std::max(0, cells[0])) * std::max(0, cells[1]) * std::max(0, cells[2]), 0);
  const std::int64_t sx = points[0];
  const std::int64_t sxy = sx * points[1];
  std::size_t id = 0;
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i, ++id)
      {
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        bool nan = false;
        for (int c = 0; c < 8; ++c)
        {
          const double v = static_cast<double>(
            data[(i + (c & 1)) + (j + ((c >> 1) & 1)) * sx + (k + ((c >> 2) & 1)) * sxy]);
          nan |= std::isnan(v);
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
        if (nan)
        {
          continue;
        }
        std::uint32_t n = 0;
        for (double iso : isovalues)
        {
          n += lo < iso && iso <= hi;
        }
        counts[id] = n;
      }
  return counts;
}

std::uint64_t HistoPyramid::GetTotal() const
{
  return this->Levels.empty() ? 0 : this->Levels.back().Counts[0];
}

std::uint32_t HistoPyramid::GetCount(int level, int i, int j, int k) const
{
  const Level& l = this->Levels[level];
  return l.Counts[(static_cast<std::size_t>(k) * l.Size[1] + j) * l.Size[0] + i];
}

void HistoPyramid::Traverse(std::uint64_t index, const double eye[3], int cell[3], int& rank) const
{
  int node[3] = { 0, 0, 0 };
  const int* baseSize = this->Levels[0].Size;
  for (int level = this->GetNumberOfLevels() - 1; level > 0; --level)
  {
    const int* size = this->Levels[level].Size;
    const int* childSize = this->Levels[level - 1].Size;
    int factor[3], nearMask = 0;
    for (int a = 0; a < 3; ++a)
    {
      factor[a] = childSize[a] / size[a];
      // Split plane of this node along a, in cell units; the near child is
      // the one on the eye's side of it.
      const double childSpan = static_cast<double>(baseSize[a]) / childSize[a];
      const double split = (2 * node[a] + 1) * childSpan;
      if (factor[a] == 2 && eye[a] >= split)
      {
        nearMask |= 1 << a;
      }
    }
    bool found = false;
    for (int order = 0; order < 8 && !found; ++order)
    {
      const int c = order ^ nearMask;
      const int d[3] = { c & 1, (c >> 1) & 1, (c >> 2) & 1 };
      if (d[0] >= factor[0] || d[1] >= factor[1] || d[2] >= factor[2])
      {
        continue;
      }
      const int child[3] = { node[0] * factor[0] + d[0], node[1] * factor[1] + d[1],
        node[2] * factor[2] + d[2] };
      const std::uint32_t count = this->GetCount(level - 1, child[0], child[1], child[2]);
      if (index < count)
      {
        node[0] = child[0];
        node[1] = child[1];
        node[2] = child[2];
        found = true;
      }
      else
      {
        index -= count;
      }
    }
  }
  cell[0] = node[0];
  cell[1] = node[1];
  cell[2] = node[2];
  rank = static_cast<int>(index);
}

#define MEDISO_INSTANTIATE(T)                                                                      \
  template std::vector<std::uint32_t> HistoPyramid::CountCrossings<T>(                             \
    const T*, const int[3], const std::vector<double>&)
MEDISO_FOR_EACH_SCALAR_TYPE(MEDISO_INSTANTIATE);
#undef MEDISO_INSTANTIATE

} // namespace mediso
