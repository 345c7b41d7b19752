// SPDX-License-Identifier: BSD-3-Clause
//
// Mesh_fs.glsl: Phong shading of a mesh with the isosurface renderer's
// lighting model (HistoPyramidIso_fs.glsl's shade()): ambient, diffuse and
// specular of the material, up to 6 lights given in view space. Two-sided as
// VTK's polygon mapper: a back-facing triangle's normal is turned around.
// MEDISO_LIGHTS, the number of lights, is a constant of the program (a
// variant per count): a software rasteriser shades the lanes of a loop bound
// by a uniform for every iteration, masked.

in vec3 viewPosition;
in vec3 viewNormal;
uniform vec4 color;              // rgb, opacity (premultiplied in the output)
uniform int parallelProjection;
uniform float ambient;
uniform float diffuse;
uniform float specular;
uniform float specularPower;
uniform vec3 lightDirections[6]; // from the surface towards the light
uniform vec3 lightColors[6];

MEDISO_OUTPUT(0) vec4 fragOutput0;

void main()
{
  vec3 n = normalize(gl_FrontFacing ? viewNormal : -viewNormal);
  vec3 toViewer = parallelProjection == 1 ? vec3(0.0, 0.0, 1.0) : -normalize(viewPosition);
  vec3 result = ambient * color.rgb;
  for (int l = 0; l < MEDISO_LIGHTS; ++l)
  {
    vec3 toLight = lightDirections[l];
    float lambert = max(dot(n, toLight), 0.0);
    result += diffuse * lambert * color.rgb * lightColors[l];
    if (lambert > 0.0 && specular > 0.0)
    {
      vec3 r = reflect(-toLight, n);
      result += specular * pow(max(dot(r, toViewer), 0.0), specularPower) * lightColors[l];
    }
  }
  fragOutput0 = vec4(result * color.a, color.a);
}
