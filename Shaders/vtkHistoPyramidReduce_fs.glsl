//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidReduce_fs.glsl: one level of the GPU HistoPyramid
// (vtkOpenGLHistoPyramid) from the level below. Drawn as one full-screen
// quad per z-slice of the GL_R32UI 3D texture of level l + 1: fragment
// (i, j) of slice k is node (i, j, k), and writes the sum of its children in
// level l, the box [2i, 2i + fx) x [2j, 2j + fy) x [2k, 2k + fz) where the
// factor f is 2 along an axis that level l still has more than one node on,
// else 1 (the layout of mediso::HistoPyramid).
//
// GLSL 1.50 only; integer output declared here, as in the base pass.

in vec2 texCoord;

uniform usampler3D lowerLevel; // GL_R32UI, texelFetch only
uniform ivec3 factor;          // 1 or 2 per axis
uniform ivec2 sliceSize;       // size of the level being written, x and y
flat in int slice;       // z of the slice being written (vtkHistoPyramidLayer_gs.glsl)

out uvec4 fragOutput0;

void main()
{
  ivec3 node = ivec3(ivec2(floor(texCoord * vec2(sliceSize))), slice);
  ivec3 first = node * factor;
  uint sum = 0u;
  for (int dz = 0; dz < factor.z; ++dz)
  {
    for (int dy = 0; dy < factor.y; ++dy)
    {
      for (int dx = 0; dx < factor.x; ++dx)
      {
        sum += texelFetch(lowerLevel, first + ivec3(dx, dy, dz), 0).r;
      }
    }
  }
  fragOutput0 = uvec4(sum, 0u, 0u, 0u);
}
