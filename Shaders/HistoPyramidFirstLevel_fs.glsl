// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidFirstLevel_fs.glsl: level 1 of the HistoPyramid, the lowest
// level mediso::HistoPyramidGL stores, straight from the volume. Levels are
// stored packed (texel (i, j, k) holds nodes (2i + a, 2j + b, k) in
// component a + 2b) in a 2D atlas (see HistoPyramidCommon.glsl); each
// fragment is one packed texel and counts its 4 nodes (main(), below).
// Node n's cells are the box [2n.x, 2n.x + fx) x [2n.y, 2n.y + fy) x
// [2n.z, 2n.z + fz) (f = 2 along an axis the base level has more than one
// cell on, else 1); the node reads the box's (f + 1)^3 <= 27 corner values
// once and counts the crossing isovalues of its cells (0 for padding cells
// and for nodes beyond level 1's size).
//
// Skipping the stored base level is what keeps the pyramid small: level 1 in
// 8 bits per node is 1/8 byte per cell, against 4 bytes per cell for a
// 32-bit base.

//MEDISO::HistoPyramidCommon

uniform ivec3 factor;    // 1 or 2 per axis (base level to level 1)
uniform ivec3 levelSize; // nodes of level 1
uniform ivec3 shifts;    // level 1's atlas (see atlasTexel())

MEDISO_OUTPUT(0) uvec4 fragOutput0;

// The crossings of node `node`, whose <= 27 corner values are p[i + 3 j +
// 9 k] (points node * factor + (i, j, k), clamped to the volume): 0 beyond
// level 1's size. With one isovalue (MEDISO_CHILD_MASKS) the node's child mask
// instead: bit X + 2 Y + 4 Z set when child cell (X, Y, Z) crosses it, the
// count being the number of bits set (the reduction to level 2 counts them;
// the walk of the drawing program then reads which cells of the node are
// active with the count it reads anyway, and recounts nothing).
uint nodeCount(ivec3 node, VALUE_TYPE p[27])
{
  if (any(greaterThanEqual(node, levelSize)))
  {
    return 0u;
  }
  ivec3 first = node * factor;
  // Each child cell's corners by constant indices (arrays indexed by
  // variables are spilled to memory by software rasterisers such as llvmpipe).
  uint sum = 0u;
#ifdef MEDISO_CHILD_MASKS
#define MEDISO_ADD_CHILD(m, c) sum |= uint(m & 1) << uint(c);
#else
#define MEDISO_ADD_CHILD(m, c) sum += bitCount8(m);
#endif
#define MEDISO_CHILD(X, Y, Z)                                                                \
  if (X < factor.x && Y < factor.y && Z < factor.z)                                         \
  {                                                                                         \
    VALUE_TYPE w[8];                                                                        \
    MEDISO_CHILD_CORNERS(w, p, X, Y, Z)                                                     \
    MEDISO_ADD_CHILD(cellMask(first + ivec3(X, Y, Z), w), X + 2 * Y + 4 * Z)                \
  }
  MEDISO_CHILD(0, 0, 0)
  MEDISO_CHILD(1, 0, 0)
  MEDISO_CHILD(0, 1, 0)
  MEDISO_CHILD(1, 1, 0)
  MEDISO_CHILD(0, 0, 1)
  MEDISO_CHILD(1, 0, 1)
  MEDISO_CHILD(0, 1, 1)
  MEDISO_CHILD(1, 1, 1)
  return sum;
}

// The 4 nodes of packed texel (i, j, k) read the points
// (4i .. 4i + 4, 4j .. 4j + 4, k fz .. k fz + 2), clamped to the volume, once:
// 2 stored texels per row of 5 points along x (the volume holds 4 points to
// a texel, see HistoPyramidCommon.glsl), 30 fetches against 4 x 27. Node
// (a, b)'s points are then those from (2a, 2b, 0) on, by constant indices.
// (Along an axis with one cell, factor 1, only node 0 exists and it starts
// at point 0 as well.)
void main()
{
  ivec3 texel = packedTexel(ivec2(gl_FragCoord.xy), shifts);
  ivec3 base = ivec3(4 * texel.xy, texel.z * factor.z);
  selectSlot(slotOfCell(base)); // a texel's 4 nodes lie in one slot (slots are 16 cells or more)
  VALUE_TYPE points[75]; // point base + (x, y, z) at x + 5 y + 25 z
  for (int r = 0; r < 15; ++r) // row r: points base + (0..4, r % 5, r / 5)
  {
    int y = min(base.y + r % 5, cellDimensions.y);
    int z = min(base.z + r / 5, cellDimensions.z);
    VALUE_VEC4 quad = pointQuad(texel.x, y, z);
    points[5 * r] = quad.x;
    points[5 * r + 1] = quad.y;
    points[5 * r + 2] = quad.z;
    points[5 * r + 3] = quad.w;
    points[5 * r + 4] = pointQuad(texel.x + 1, y, z).x;
  }
  uint counts[4];
  for (int n = 0; n < 4; ++n) // node (a, b) = (n & 1, n >> 1)
  {
    VALUE_TYPE p[27];
    for (int i = 0; i < 27; ++i)
    {
      p[i] = points[2 * (n & 1) + i % 3 + 5 * (2 * (n >> 1) + (i / 3) % 3) + 25 * (i / 9)];
    }
    counts[n] = nodeCount(ivec3(2 * texel.xy + ivec2(n & 1, n >> 1), texel.z), p);
  }
  fragOutput0 = uvec4(counts[0], counts[1], counts[2], counts[3]);
}
