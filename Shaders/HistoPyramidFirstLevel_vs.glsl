// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidFirstLevel_vs.glsl: the rectangles of the level-1 pass
// (HistoPyramidFirstLevel_fs.glsl). Level 1's atlas is cleared to 0 and only
// the tiles an isovalue can cross are drawn: mediso::HistoPyramidGL keeps,
// per tile (TileTexels x TileTexels packed texels of one slice), the range of
// the point values its cells read, and for each build merges the runs of
// active tiles along x into rectangles, two triangles each, given here in
// atlas texels. Everything else keeps its 0 and costs no fragment.

in vec2 vertexInput0;       // a rectangle's corner, in atlas texels
uniform vec2 atlasSize;    // level 1's atlas, in texels

void main()
{
  gl_Position = vec4(2.0 * vertexInput0 / atlasSize - 1.0, 0.0, 1.0);
}
