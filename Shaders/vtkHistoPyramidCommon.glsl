// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidCommon.glsl: the one definition of an "active cell" shared by
// every HistoPyramid shader (the build passes and the isosurface drawing
// program), so that the pyramid's counts and the traversal that reads them
// can never disagree. vtkOpenGLHistoPyramid puts this text in place of the
// //VTK::HistoPyramidCommon::Dec line of each shader, after the #defines of
// the volume's value type:
//   VALUE_SAMPLER  isampler3D, usampler3D or sampler3D
//   VALUE_TYPE     int, uint or float
//   VALUE_IS_FLOAT defined for float data (NaN corners make a cell inactive)
//
// The isovalues arrive as thresholds of the volume's own value type, computed
// on the CPU so that "lo < t && t <= hi" here is exactly "lo < iso && iso <=
// hi" in double precision (ceil(iso) for integer data, the smallest float not
// below iso for float data), in increasing order; isovalues that can cross no
// cell are dropped before they get here.

uniform VALUE_SAMPLER volume;      // point values, read with texelFetch only
uniform VALUE_TYPE thresholds[8];  // see above
uniform int numberOfThresholds;    // 0 .. 8
uniform ivec3 cellDimensions;      // real cells per axis (points - 1)

// Bit t set when isovalue t crosses a cell whose corner values span [lo, hi].
// A constant bound, so that the loop unrolls: llvmpipe's LLVM takes time
// exponential in the number of loops in a chain (a shader inlines this once
// per cell it classifies), and a uniform bound would keep each one a loop.
int crossingMask(VALUE_TYPE lo, VALUE_TYPE hi)
{
  int mask = 0;
  for (int t = 0; t < 8; ++t)
  {
    if (t < numberOfThresholds && lo < thresholds[t] && thresholds[t] <= hi)
    {
      mask |= 1 << t;
    }
  }
  return mask;
}

// Number of set bits of a crossing mask (at most 8 bits are used).
uint bitCount8(int mask)
{
  uint n = 0u;
  for (int t = 0; t < 8; ++t)
  {
    n += uint((mask >> t) & 1);
  }
  return n;
}

// Crossing mask of cell c (0 outside the real cell grid and, for float data,
// for a cell with a NaN corner), from its corner values v[0..7], corner
// (dx, dy, dz) at index dx + 2 dy + 4 dz.
int cellMask(ivec3 c, VALUE_TYPE v[8])
{
  if (any(greaterThanEqual(c, cellDimensions)))
  {
    return 0;
  }
  VALUE_TYPE lo = v[0];
  VALUE_TYPE hi = v[0];
#ifdef VALUE_IS_FLOAT
  bool nan = isnan(v[0]);
#endif
  for (int i = 1; i < 8; ++i)
  {
#ifdef VALUE_IS_FLOAT
    nan = nan || isnan(v[i]);
#endif
    lo = min(lo, v[i]);
    hi = max(hi, v[i]);
  }
#ifdef VALUE_IS_FLOAT
  if (nan)
  {
    return 0;
  }
#endif
  return crossingMask(lo, hi);
}

// The corner values of cell c (which must lie in the real cell grid).
void fetchCorners(ivec3 c, out VALUE_TYPE v[8])
{
  for (int i = 0; i < 8; ++i)
  {
    v[i] = texelFetch(volume, c + ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1), 0).r;
  }
}

// The 8 corner values w[0..7] of child cell (X, Y, Z) (each 0 or 1, literal)
// of a 2x2x2 node whose 27 point values are p[i + 3 j + 9 k]. A macro with
// literal indices: software rasterisers spill variably indexed arrays.
#define MEDISO_CHILD_CORNERS(w, p, X, Y, Z)                                                 \
  w[0] = p[X + 3 * Y + 9 * Z];                                                              \
  w[1] = p[X + 1 + 3 * Y + 9 * Z];                                                          \
  w[2] = p[X + 3 * (Y + 1) + 9 * Z];                                                        \
  w[3] = p[X + 1 + 3 * (Y + 1) + 9 * Z];                                                    \
  w[4] = p[X + 3 * Y + 9 * (Z + 1)];                                                        \
  w[5] = p[X + 1 + 3 * Y + 9 * (Z + 1)];                                                    \
  w[6] = p[X + 3 * (Y + 1) + 9 * (Z + 1)];                                                  \
  w[7] = p[X + 1 + 3 * (Y + 1) + 9 * (Z + 1)];
