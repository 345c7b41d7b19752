//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidFirstLevel_fs.glsl: level 1 of the HistoPyramid, the lowest
// level vtkOpenGLHistoPyramid stores, straight from the volume. Drawn as one
// full-screen quad per z-slice: fragment (i, j) of slice k is node (i, j, k),
// whose cells are the box [2i, 2i + fx) x [2j, 2j + fy) x [2k, 2k + fz)
// (f = 2 along an axis the base level has more than one cell on, else 1). It
// reads the box's (f + 1)^3 <= 27 corner values once and writes the summed
// number of crossing isovalues of its cells (0 for padding cells).
//
// Skipping the stored base level is what keeps the pyramid small: level 1 in
// GL_R8UI is 1/8 byte per cell, against 4 bytes per cell for an R32UI base.
//
// GLSL 1.50 only; integer output declared here.

//VTK::HistoPyramidCommon::Dec

in vec2 texCoord;

uniform ivec3 factor;    // 1 or 2 per axis (base level to level 1)
uniform ivec2 sliceSize; // size of level 1 in x and y
flat in int slice;       // z of the slice being written (vtkHistoPyramidLayer_gs.glsl)

out uvec4 fragOutput0;

void main()
{
  ivec3 node = ivec3(ivec2(floor(texCoord * vec2(sliceSize))), slice);
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
  fragOutput0 = uvec4(sum, 0u, 0u, 0u);
}
