// SPDX-License-Identifier: BSD-3-Clause
#include "HistoPyramid.h"

#include "ScalarTypes.h"

#include <algorithm>
#include <cmath>

namespace mediso
{
void HistoPyramid::Build(const int cells[3], const std::vector<std::uint32_t>& baseCounts)
{
  this->Layout = PyramidLayout(cells);
  const PyramidLayout& layout = this->Layout;
  this->Counts.assign(static_cast<std::size_t>(layout.GetNumberOfLevels()), {});
  const auto& base = layout.Size(0);
  std::vector<std::uint32_t>& level0 = this->Counts[0];
  level0.assign(static_cast<std::size_t>(base[0]) * base[1] * base[2], 0);
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i)
        level0[(static_cast<std::size_t>(k) * base[1] + j) * base[0] + i] =
          baseCounts[(static_cast<std::size_t>(k) * cells[1] + j) * cells[0] + i];

  // Each level sums the children of its nodes in the level below.
  for (int l = 1; l < layout.GetNumberOfLevels(); ++l)
  {
    const auto& size = layout.Size(l);
    const auto& lower = layout.Size(l - 1);
    const auto factor = layout.Factor(l);
    const std::vector<std::uint32_t>& below = this->Counts[l - 1];
    std::vector<std::uint32_t>& up = this->Counts[l];
    up.assign(static_cast<std::size_t>(size[0]) * size[1] * size[2], 0);
    for (int k = 0; k < size[2]; ++k)
      for (int j = 0; j < size[1]; ++j)
        for (int i = 0; i < size[0]; ++i)
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
            sum += below[(static_cast<std::size_t>(z) * lower[1] + y) * lower[0] + x];
          }
          up[(static_cast<std::size_t>(k) * size[1] + j) * size[0] + i] = sum;
        }
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
  return this->Counts.empty() ? 0 : this->Counts.back()[0];
}

std::uint32_t HistoPyramid::GetCount(int level, int i, int j, int k) const
{
  const auto& size = this->Layout.Size(level);
  return this->Counts[level][(static_cast<std::size_t>(k) * size[1] + j) * size[0] + i];
}

void HistoPyramid::Traverse(std::uint64_t index, const double eye[3], int cell[3], int& rank) const
{
  int node[3] = { 0, 0, 0 };
  for (int level = this->GetNumberOfLevels() - 1; level > 0; --level)
  {
    const auto factor = this->Layout.Factor(level);
    const auto childSpan = this->Layout.CellsPerNode(level - 1);
    int nearMask = 0;
    for (int a = 0; a < 3; ++a)
    {
      // Split plane of this node along a, in cell units; the near child is
      // the one on the eye's side of it.
      const double split = (2.0 * node[a] + 1.0) * childSpan[a];
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
