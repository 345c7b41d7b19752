//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidIso_gs.glsl: geometry stage of vtkHistoPyramidIsoMapper.
// Turns the point of one active cell into the cell's screen footprint: the
// faces of the cell box that face the eye (1 to 3 quads). The front faces of
// a convex box cover its whole silhouette exactly once, at any zoom and in
// perspective or parallel projection, and the rasteriser clips them like
// any geometry: no point sprite (GL_POINT_SIZE_RANGE caps those) and no
// screen-space bounding box that breaks down near the eye. When the eye is
// inside the cell no face faces it; then all six faces are drawn (seen from
// inside, every pixel is covered by exactly one of them).
//
// Positions are passed on in cell-index space; the fragment stage casts the
// ray from the eye through them.

layout(points) in;
layout(triangle_strip, max_vertices = 24) out;

uniform mat4 indexToClip; // cell-index space to clip coordinates
uniform vec4 eyeIndex;    // eye, homogeneous, in cell-index space

flat in ivec3 vCell[];
flat in int vMask[];
flat in int vIsovalue[];
flat in vec4 vLook[];
flat in vec4 vLow[];
flat in vec4 vHigh[];
in CornerGradients
{
  flat vec3 g[8];
} vGradients[];

out vec3 gPosition;       // cell-index space
flat out ivec3 gCell;
flat out int gMask;
flat out vec4 gLook;
flat out vec4 gLow;
flat out vec4 gHigh;
flat out vec3 gGradients[8];

void emitCorner(vec3 position)
{
  gPosition = position;
  gCell = vCell[0];
  gMask = vMask[0];
  gLook = vLook[0];
  gLow = vLow[0];
  gHigh = vHigh[0];
  for (int i = 0; i < 8; ++i)
  {
    gGradients[i] = vGradients[0].g[i];
  }
  gl_Position = indexToClip * vec4(position, 1.0);
  EmitVertex();
}

// The face of the cell at coordinate `side` (0 or 1) along `axis`.
void emitFace(vec3 origin, int axis, float side)
{
  int u = (axis + 1) % 3;
  int v = (axis + 2) % 3;
  for (int k = 0; k < 4; ++k)
  {
    vec3 corner = vec3(0.0);
    corner[axis] = side;
    corner[u] = float(k & 1);
    corner[v] = float(k >> 1);
    emitCorner(origin + corner);
  }
  EndPrimitive();
}

void main()
{
  if (vIsovalue[0] < 0)
  {
    return;
  }
  vec3 low = vec3(vCell[0]);
  vec3 high = low + 1.0;
  int faces = 0;
  for (int a = 0; a < 3; ++a)
  {
    if (eyeIndex[a] - low[a] * eyeIndex.w < 0.0)
    {
      emitFace(low, a, 0.0);
      ++faces;
    }
    else if (eyeIndex[a] - high[a] * eyeIndex.w > 0.0)
    {
      emitFace(low, a, 1.0);
      ++faces;
    }
  }
  if (faces == 0)
  {
    for (int a = 0; a < 3; ++a)
    {
      emitFace(low, a, 0.0);
      emitFace(low, a, 1.0);
    }
  }
}
