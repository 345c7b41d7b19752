//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidLayer_vs.glsl: full-screen quads for the HistoPyramid build
// passes, one per z-slice of the 3D texture being written, all in one draw
// call: glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, slices) with no vertex
// attributes. Instance i is slice i; vtkHistoPyramidLayer_gs.glsl sends it to
// layer i of the layered framebuffer attachment (gl_Layer, OpenGL 3.2 core).
// One draw per level instead of one per slice: every draw and framebuffer
// change costs a flush on software rasterisers such as llvmpipe.

out vec2 vTexCoord;
flat out int vSlice;

void main()
{
  vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
  vTexCoord = corner;
  vSlice = gl_InstanceID;
  gl_Position = vec4(2.0 * corner - 1.0, 0.0, 1.0);
}
