//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidFirstLevel_gs.glsl: one quad, on its slice's layer, for each
// active tile of vtkHistoPyramidFirstLevel_vs.glsl, nothing for the others.
// texCoord is the texel position over the slice's size (fragment centres at
// (i + 0.5) / width, as with the full-slice quads of
// vtkHistoPyramidLayer_vs.glsl), so the fragment stage is the same.

layout(points) in;
layout(triangle_strip, max_vertices = 4) out;

uniform ivec2 sliceSize;

flat in int vActive[];
flat in int vSlice[];
flat in vec4 vRect[];

out vec2 texCoord;
flat out int slice;

void main()
{
  if (vActive[0] == 0)
  {
    return;
  }
  for (int i = 0; i < 4; ++i)
  {
    vec2 corner = vec2(float(i & 1), float((i >> 1) & 1));
    vec2 texel = mix(vRect[0].xy, vRect[0].zw, corner);
    texCoord = texel / vec2(sliceSize);
    gl_Position = vec4(2.0 * texCoord - 1.0, 0.0, 1.0);
    gl_Layer = vSlice[0];
    slice = vSlice[0];
    EmitVertex();
  }
  EndPrimitive();
}
