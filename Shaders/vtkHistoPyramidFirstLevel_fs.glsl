//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidFirstLevel_fs.glsl: level 1 of the HistoPyramid, the lowest
// level vtkOpenGLHistoPyramid stores, straight from the volume. Levels are
// stored packed (see vtkHistoPyramidReduce_fs.glsl): texel (i, j, k) holds
// the counts of the 2x2 nodes (2i + a, 2j + b, k) in component a + 2b. Drawn
// as a quad per tile of a z-slice, for the tiles an isovalue can cross
// (vtkHistoPyramidFirstLevel_vs.glsl; the others keep the 0 the level is
// cleared to); each fragment counts its 4 nodes.
// Node n's cells are the box [2n.x, 2n.x + fx) x [2n.y, 2n.y + fy) x
// [2n.z, 2n.z + fz) (f = 2 along an axis the base level has more than one
// cell on, else 1); the node reads the box's (f + 1)^3 <= 27 corner values
// once and counts the crossing isovalues of its cells (0 for padding cells
// and for nodes beyond level 1's size).
//
// Skipping the stored base level is what keeps the pyramid small: level 1 in
// 8 bits per node is 1/8 byte per cell, against 4 bytes per cell for a
// 32-bit base.
//
// GLSL 1.50 only; integer output declared here.

//VTK::HistoPyramidCommon::Dec

in vec2 texCoord;

uniform ivec3 factor;    // 1 or 2 per axis (base level to level 1)
uniform ivec2 sliceSize; // packed size of level 1 in x and y
uniform ivec3 levelSize; // nodes of level 1
flat in int slice;       // z of the slice being written (vtkHistoPyramidLayer_gs.glsl)

out uvec4 fragOutput0;

uint nodeCount(ivec3 node)
{
  if (any(greaterThanEqual(node, levelSize)))
  {
    return 0u;
  }
  ivec3 first = node * factor;
  ivec3 pointMax = cellDimensions; // last point index per axis
  VALUE_TYPE p[27];
  for (int i = 0; i < 27; ++i)
  {
    ivec3 d = ivec3(i % 3, (i / 3) % 3, i / 9);
    p[i] = texelFetch(volume, min(first + d, pointMax), 0).r;
  }
  // Each child cell's corners by constant indices (arrays indexed by
  // variables are spilled to memory by software rasterisers such as llvmpipe).
  uint sum = 0u;
#define MEDISO_CHILD(X, Y, Z)                                                                \
  if (X < factor.x && Y < factor.y && Z < factor.z)                                         \
  {                                                                                         \
    VALUE_TYPE w[8];                                                                        \
    MEDISO_CHILD_CORNERS(w, p, X, Y, Z)                                                     \
    sum += bitCount8(cellMask(first + ivec3(X, Y, Z), w));                                  \
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

//VTK::HistoPyramidPacked::Impl
