//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidFirstLevel_vs.glsl: the tiles of the level-1 pass
// (vtkHistoPyramidFirstLevel_fs.glsl). Each z-slice of the packed level 1 is
// cut into tiles of tileSize x tileSize texels; vertex i of one
// glDrawArrays(GL_POINTS) is tile (i % tiles.x, (i / tiles.x) % tiles.y) of
// slice i / (tiles.x tiles.y). vtkOpenGLHistoPyramid computes, once per
// volume, the range of the point values each tile's cells read
// (tileRanges: min in .r, max in .g, of the volume's own value type); a tile
// holds an active cell only if an isovalue lies in that range, by the same
// crossing test as a cell (min < t <= max over more points is necessary for
// every cell under the tile). vtkHistoPyramidFirstLevel_gs.glsl turns the
// active tiles into quads on their slice and drops the others: their
// texels keep the 0 the level was cleared to, and their fragments, most of
// the volume for a typical isovalue, are never run. On a software
// rasteriser the pass costs what it draws: an `if` or a `discard` in the
// fragment stage would still run, or compile, the counting for every texel.

//VTK::HistoPyramidCommon::Dec

uniform ivec2 tiles;       // tiles per slice, x and y
uniform int tileSize;      // texels per tile side
uniform ivec2 sliceSize;   // packed size of level 1 in x and y
uniform VALUE_SAMPLER tileRanges; // per tile: the least (.r) and greatest (.g) value

flat out int vActive;      // 1: some isovalue may cross a cell of the tile
flat out int vSlice;
flat out vec4 vRect;       // the tile's texels, [x0, x1) x [y0, y1), in texels

void main()
{
  int perSlice = tiles.x * tiles.y;
  int slice = gl_VertexID / perSlice;
  int inSlice = gl_VertexID - slice * perSlice;
  ivec2 tile = ivec2(inSlice % tiles.x, inSlice / tiles.x);
  VALUE_TYPE lo = texelFetch(tileRanges, ivec3(tile, slice), 0).r;
  VALUE_TYPE hi = texelFetch(tileRanges, ivec3(tile, slice), 0).g;
  vActive = crossingMask(lo, hi) != 0 ? 1 : 0;
  vSlice = slice;
  ivec2 first = tile * tileSize;
  vRect = vec4(vec2(first), vec2(min(first + tileSize, sliceSize)));
  gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
