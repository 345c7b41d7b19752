// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidFullScreen_vs.glsl: one triangle that covers the viewport,
// drawn with glDrawArrays(GL_TRIANGLES, 0, 3) and no vertex attributes
// (gl_VertexID only: OpenGL 3.2 core and OpenGL ES 3.0 alike). The passes
// that write a whole stored level of the HistoPyramid (its 2D atlas is the
// viewport), and the first-hit composite, draw with it; their fragment
// stages work from gl_FragCoord.

void main()
{
  vec2 corner = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1));
  gl_Position = vec4(corner - 1.0, 0.0, 1.0);
}
