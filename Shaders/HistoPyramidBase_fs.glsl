// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidBase_fs.glsl: the base level of the HistoPyramid (one count
// per cell), for inspection only. mediso::HistoPyramidGL never stores this
// level (the first stored level, HistoPyramidFirstLevel_fs.glsl, counts
// cells itself, and the drawing program's walk finds the cells of its last
// node from the volume): HistoPyramidGL::ReadLevel(0) draws this pass into a
// temporary R32UI atlas, one count per texel (slices laid out as in
// atlasTexel(), unpacked), so that tests can compare every cell with the CPU.

//MEDISO::HistoPyramidCommon

uniform ivec3 shifts; // the base atlas: log2 of the slice's width and height, of the columns

MEDISO_OUTPUT(0) uvec4 fragOutput0;

void main()
{
  ivec3 cell = packedTexel(ivec2(gl_FragCoord.xy), shifts);
  uint count = 0u;
  if (all(lessThan(cell, cellDimensions)))
  {
    VALUE_TYPE v[8];
    selectSlot(slotOfCell(cell));
    fetchCorners(cell, v);
    count = bitCount8(cellMask(cell, v));
  }
  fragOutput0 = uvec4(count, 0u, 0u, 0u);
}
