// SPDX-License-Identifier: BSD-3-Clause
//
// Mesh_vs.glsl: triangles with a normal per point (the web page's CPU path
// and the surfaces the server makes), in world space.

in vec3 vertexInput0; // position
in vec3 vertexInput1; // normal
uniform mat4 worldToView;
uniform mat4 projection;
uniform mat3 normalToView;
out vec3 viewPosition;
out vec3 viewNormal;

void main()
{
  vec4 p = worldToView * vec4(vertexInput0, 1.0);
  viewPosition = p.xyz;
  viewNormal = normalToView * vertexInput1;
  gl_Position = projection * p;
}
