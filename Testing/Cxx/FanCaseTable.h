// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FanCaseTable.h
 * @brief A marching-cubes case table of the VTK-free core tests' own (the
 * core takes the table as data): each case fans triangles over its cut
 * edges, min(5, cut edges - 2) of them, so that a test can count a surface's
 * triangles by brute force without VTK's table.
 */
#ifndef FanCaseTable_h
#define FanCaseTable_h

#include <algorithm>

namespace medical_test
{
// Corners and edges in vtkMarchingCubes' numbering (the layout the core expects).
inline constexpr int Corner[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 },
  { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
inline constexpr int Edge[12][2] = { { 0, 1 }, { 1, 2 }, { 3, 2 }, { 0, 3 }, { 4, 5 }, { 5, 6 },
  { 7, 6 }, { 4, 7 }, { 0, 4 }, { 1, 5 }, { 3, 7 }, { 2, 6 } };

struct FanTable
{
  int Cases[256][16];
  int Count[256];
  FanTable()
  {
    for (int c = 0; c < 256; ++c)
    {
      int cut[12], n = 0;
      for (int e = 0; e < 12; ++e)
      {
        if (((c >> Edge[e][0]) & 1) != ((c >> Edge[e][1]) & 1))
        {
          cut[n++] = e;
        }
      }
      this->Count[c] = n >= 3 ? std::min(5, n - 2) : 0;
      int* out = this->Cases[c];
      for (int i = 0; i < 16; ++i)
      {
        out[i] = -1;
      }
      for (int t = 0; t < this->Count[c]; ++t)
      {
        out[3 * t] = cut[0];
        out[3 * t + 1] = cut[t + 1];
        out[3 * t + 2] = cut[t + 2];
      }
    }
  }
};
/// The table, made once.
inline const FanTable FanCases;
} // namespace medical_test

#endif
