// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidCommon.glsl: the one definition of an "active cell" shared by
// every HistoPyramid shader (the build passes and the isosurface drawing
// program), so that the pyramid's counts and the traversal that reads them
// can never disagree, and the addressing of the stored levels. The GPU core
// (mediso::HistoPyramidGL) puts this text in place of the
// //MEDISO::HistoPyramidCommon line of each shader, after the #defines of
// the volume's value type:
//   VALUE_SAMPLER  isampler3D, usampler3D or sampler3D
//   VALUE_TYPE     int, uint or float
//   VALUE_VEC4     ivec4, uvec4 or vec4
//   VALUE_IS_FLOAT defined for float data (NaN corners make a cell inactive)
//
// The isovalues arrive as thresholds of the volume's own value type, computed
// on the CPU so that "lo < t && t <= hi" here is exactly "lo < iso && iso <=
// hi" in double precision (ceil(iso) for integer data, the smallest float not
// below iso for float data), in increasing order; isovalues that can cross no
// cell are dropped before they get here.

uniform VALUE_SAMPLER volume;      // point values, 4 to a texel; read with texelFetch only
uniform VALUE_TYPE thresholds[8];  // see above
uniform int numberOfThresholds;    // 0 .. 8
uniform ivec3 cellDimensions;      // real cells per axis (points - 1)
uniform ivec3 ownedCellsFirst;     // the cells that count: [first, end) per axis (every cell,
uniform ivec3 ownedCellsEnd;       // or those a brick owns: its apron is read, never counted)

// A brick pool (MEDISO_BRICK_POOL; IsosurfaceScene's bricks in one texture):
// the volume texture is a grid of slots, each 2^slotShift points a side,
// each holding one brick's points (with the apron its cells and gradients
// read) from the slot's point 0, or nothing. The slot table (the
// indirection, one row per slot: x + slotsPerAxis.x (y + slotsPerAxis.y z))
// holds, slot-local, the cells its brick owns, [first, end) (empty for an
// empty slot or an inactive brick's), the brick's cells (its points - 1) and
// where the slot's point 0 lies in the volume. Every shader selects the slot
// of the cells it works on (selectSlot()); without a pool the one "slot" is
// the whole volume, and the same code reads as before.
#ifdef MEDISO_BRICK_POOL
uniform usampler2D slotTable; // columns: (owned first, placement.x), (owned end, placement.y),
                              // (brick cells, placement.z)
uniform int slotShift;
uniform ivec3 slotsPerAxis;
#endif

ivec3 slotOrigin;     // the slot's point 0 in the texture
ivec3 slotCells;      // the brick's cells: its reads clamp to [slotOrigin, slotOrigin + slotCells]
ivec3 slotOwnedFirst; // the cells that count, slot-local
ivec3 slotOwnedEnd;
ivec3 slotPlacement;  // the volume's point at the slot's point 0

// The slot (per axis) of texture cell c.
ivec3 slotOfCell(ivec3 c)
{
#ifdef MEDISO_BRICK_POOL
  return c >> slotShift;
#else
  return ivec3(0);
#endif
}

void selectSlot(ivec3 slot)
{
#ifdef MEDISO_BRICK_POOL
  int row = slot.x + slotsPerAxis.x * (slot.y + slotsPerAxis.y * slot.z);
  ivec4 a = ivec4(texelFetch(slotTable, ivec2(0, row), 0));
  ivec4 b = ivec4(texelFetch(slotTable, ivec2(1, row), 0));
  ivec4 e = ivec4(texelFetch(slotTable, ivec2(2, row), 0));
  slotOrigin = slot << slotShift;
  slotOwnedFirst = a.xyz;
  slotOwnedEnd = b.xyz;
  slotCells = e.xyz;
  slotPlacement = ivec3(a.w, b.w, e.w);
  if (any(greaterThanEqual(slot, slotsPerAxis))) // the pyramid's padding: no slot, no cell
  {
    slotOwnedEnd = slotOwnedFirst;
  }
#else
  slotOrigin = ivec3(0);
  slotCells = cellDimensions;
  slotOwnedFirst = ownedCellsFirst;
  slotOwnedEnd = ownedCellsEnd;
  slotPlacement = ivec3(0);
#endif
}

// The volume is stored 4 points to a texel along x: texel (i, j, k) holds
// points (4 i + c, j, k) in component c, and the last texel of a row repeats
// the row's last point where the points run out (HistoPyramidGL's
// PackVolumeRows(); same bytes as one point per texel). The passes that read
// whole rows of points (a level-1 node's, a packed texel of level 1's) then
// need a fetch per 4 points instead of one per point.

// Points 4 texelX .. 4 texelX + 3 of row (y, z) (y, z inside the slot);
// past the row's end every one is the row's last point, as a clamp gives.
VALUE_VEC4 pointQuad(int texelX, int y, int z)
{
  int last = (slotOrigin.x + slotCells.x) >> 2; // the row's last texel (slots start at a texel)
  VALUE_VEC4 quad = texelFetch(volume, ivec3(min(texelX, last), y, z), 0);
  return texelX <= last ? quad : quad.wwww;
}

// The value of point p (inside the volume).
VALUE_TYPE pointValue(ivec3 p)
{
  VALUE_VEC4 quad = texelFetch(volume, ivec3(p.x >> 2, p.yz), 0);
  int c = p.x & 3;
  return c < 2 ? (c == 0 ? quad.x : quad.y) : (c == 2 ? quad.z : quad.w);
}

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

// Number of set bits of each of 4 masks of at most 8 bits (crossing masks,
// level 1's child masks): the one popcount of the shaders, since GLSL ES 3.00
// has no bitCount(). Pairs, then nibbles, then the byte.
uvec4 bitCount8(uvec4 m)
{
  m = (m & 0x55u) + ((m >> 1u) & 0x55u);
  m = (m & 0x33u) + ((m >> 2u) & 0x33u);
  return (m & 0x0Fu) + (m >> 4u);
}

uint bitCount8(int mask)
{
  return bitCount8(uvec4(uint(mask), 0u, 0u, 0u)).x;
}

// Crossing mask of cell c (0 outside the selected slot's owned cells, which
// lie in the real cell grid, and, for float data, for a cell with a NaN
// corner), from its corner values v[0..7], corner (dx, dy, dz) at index
// dx + 2 dy + 4 dz.
int cellMask(ivec3 c, VALUE_TYPE v[8])
{
  ivec3 local = c - slotOrigin;
  if (any(lessThan(local, slotOwnedFirst)) || any(greaterThanEqual(local, slotOwnedEnd)))
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
    v[i] = pointValue(c + ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
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

// The stored levels are 2D atlases (mediso::PyramidLayout): packed texel
// (x, y, z) of a level lies at atlas texel (x + (z % C) px, y + (z / C) py),
// with px x py packed texels per slice and C slices per atlas row, all
// powers of two. A level's layout is given as shifts: (log2 px, log2 py,
// log2 C).
ivec2 atlasTexel(ivec3 t, ivec3 shifts)
{
  int columnMask = (1 << shifts.z) - 1;
  return ivec2(t.x + ((t.z & columnMask) << shifts.x), t.y + ((t.z >> shifts.z) << shifts.y));
}

// The packed texel (x, y, z) of a level at atlas texel a (the inverse).
ivec3 packedTexel(ivec2 a, ivec3 shifts)
{
  ivec2 slice = ivec2(a.x >> shifts.x, a.y >> shifts.y);
  return ivec3(a.x & ((1 << shifts.x) - 1), a.y & ((1 << shifts.y) - 1),
    (slice.y << shifts.z) | slice.x);
}
