// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidPacked.glsl: the packed layout of the stored HistoPyramid
// levels, for the reductions that write levels 2 and up.
// vtkOpenGLHistoPyramid puts this text in place of the
// //VTK::HistoPyramidPacked::Impl line of their fragment shader, which
// defines uint nodeCount(ivec3 node) (0 for a node beyond the level). Level 1
// (vtkHistoPyramidFirstLevel_fs.glsl) writes the same layout with a main() of
// its own, which reads its 4 nodes' points once.
//
// Texel (i, j, k) of a stored level holds the counts of the 2x2 nodes
// (2i + a, 2j + b, k) in component a + 2b; the mapper's walk
// (vtkHistoPyramidIso_vs.glsl, descend()) and vtkOpenGLHistoPyramid::
// ReadLevel() read it the same way. Drawn as one full-screen quad per
// z-slice of the packed level (vtkHistoPyramidLayer_gs.glsl gives the slice).

void main()
{
  ivec3 texel = ivec3(ivec2(floor(texCoord * vec2(sliceSize))), slice);
  ivec3 first = ivec3(2 * texel.xy, texel.z);
  fragOutput0 = uvec4(nodeCount(first), nodeCount(first + ivec3(1, 0, 0)),
    nodeCount(first + ivec3(0, 1, 0)), nodeCount(first + ivec3(1, 1, 0)));
}
