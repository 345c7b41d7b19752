//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidLayer_gs.glsl: routes each quad of vtkHistoPyramidLayer_vs.glsl
// to the layer (z-slice) of its instance, and passes the slice on to the
// fragment stage of the pass.

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec2 vTexCoord[];
flat in int vSlice[];

out vec2 texCoord;
flat out int slice;

void main()
{
  for (int i = 0; i < 3; ++i)
  {
    gl_Layer = vSlice[0];
    slice = vSlice[0];
    texCoord = vTexCoord[i];
    gl_Position = gl_in[i].gl_Position;
    EmitVertex();
  }
  EndPrimitive();
}
