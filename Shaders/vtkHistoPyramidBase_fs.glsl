//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidBase_fs.glsl: the base level of the HistoPyramid (one count
// per cell), for inspection only. vtkOpenGLHistoPyramid never stores this
// level (the first stored level, vtkHistoPyramidFirstLevel_fs.glsl, counts
// cells itself, and the traversal recounts the cells of its last node from
// the volume): vtkOpenGLHistoPyramid::ReadLevel(0) draws this pass into a
// temporary texture so that tests can compare every cell with the CPU.
// Drawn as one full-screen quad per z-slice (all slices in one layered draw): fragment (i, j) of slice k is
// cell (i, j, k) and writes the number of isovalues crossing it (0 for the
// padding cells beyond the real cell grid).
//
// GLSL 1.50 only. Integer output: no "//VTK::Output::Dec" line, the shader
// declares its own uvec4 output (see vtkMedicalProbe_fs.glsl for why). The
// cell index comes from texCoord (which also keeps the quad helper's
// texCoordIn attribute alive): fragment centres sit at (i + 0.5) / width.

//VTK::HistoPyramidCommon::Dec

in vec2 texCoord;

uniform ivec2 sliceSize; // level-0 size in x and y (powers of two)
flat in int slice;       // z of the slice being written (vtkHistoPyramidLayer_gs.glsl)

out uvec4 fragOutput0;

void main()
{
  ivec3 cell = ivec3(ivec2(floor(texCoord * vec2(sliceSize))), slice);
  uint count = 0u;
  if (all(lessThan(cell, cellDimensions)))
  {
    VALUE_TYPE v[8];
    fetchCorners(cell, v);
    count = bitCount8(cellMask(cell, v));
  }
  fragOutput0 = uvec4(count, 0u, 0u, 0u);
}
