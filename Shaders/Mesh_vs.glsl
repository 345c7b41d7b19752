// SPDX-License-Identifier: BSD-3-Clause
//
// Mesh_vs.glsl: triangles with a normal per point (the web page's CPU path
// and the surfaces the server makes), in world space. Positions come packed
// as normalized 16-bit integers within the mesh's bounds, normals as
// normalized signed bytes (MeshRenderer.cxx, PackVertices).

in vec4 vertexInput0; // position in [0, 1] along each axis of the mesh's bounds
in vec3 vertexInput1; // normal, not of unit length
uniform vec3 positionOffset; // the bounds' low corner
uniform vec3 positionScale;  // the bounds' extent
uniform mat4 worldToView;
uniform mat4 projection;
uniform mat3 normalToView;
out vec3 viewPosition;
out vec3 viewNormal;

void main()
{
  vec4 p = worldToView * vec4(positionOffset + positionScale * vertexInput0.xyz, 1.0);
  viewPosition = p.xyz;
  viewNormal = normalToView * vertexInput1;
  gl_Position = projection * p;
}
