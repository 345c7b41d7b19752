//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkMedicalProbe_fs.glsl: fragment shader of the functional probe of
// vtkMedicalGLCapabilities. It does, on a tiny volume, exactly what the base
// level of the HistoPyramid mapper does: read an int16 volume stored as a
// GL_RGBA16I 3D texture (4 points to a texel along x, as the mapper stores a
// volume) with texelFetch, classify cells against an isovalue and write an
// unsigned integer count per fragment into a GL_R32UI render target.
//
// vtkOpenGLShaderCache replaces the first line with "#version 150" (OpenGL 3.2
// core, GLSL 1.50) plus a few portability #defines. Only GLSL 1.50 is used:
// no compute shaders, no shader storage buffers, no explicit layout locations.
//
// Drawn as one full-screen quad (vtkOpenGLQuadHelper) over a target of
// (nx - 1) x (ny - 1) texels: fragment (i, j) writes the number of ACTIVE
// cells in the cell column (i, j, k = 0 .. nz - 2). A cell is active when its
// eight corner values straddle the isovalue, min < isovalue <= max, i.e. its
// marching-cubes case index (corner "inside" when value >= isovalue) is
// neither 0 nor 255.
//
// The column index comes from the quad's texCoord: fragment centres sit at
// texCoord = (i + 0.5) / (nx - 1), so floor(texCoord * (nx - 1)) = i. (Using
// texCoord, rather than gl_FragCoord, also keeps the vertex attribute
// texCoordIn active: vtkOpenGLQuadHelper reports an error when the linker has
// optimised it away.)
//
// Integer output: there is deliberately no "//VTK::Output::Dec" line and no
// gl_FragData[] here. vtkOpenGLShaderCache only declares outputs for
// gl_FragData[n] uses, always as "out vec4 fragOutputN", which cannot feed an
// unsigned integer colour buffer. So the shader declares its own uvec4
// output, named like VTK's (fragOutput0); as the only output of the program
// it gets location 0 (vtkMedicalGLCapabilities checks this with
// glGetFragDataLocation), i.e. GL_COLOR_ATTACHMENT0.

in vec2 texCoord;

uniform isampler3D probeVolume; // GL_RGBA16I, nearest filtering, read with texelFetch only
uniform ivec3 probePoints;      // points per axis (texel (i, j, k) holds points 4i .. 4i + 3)
uniform float isovalue;         // int16 values are exact in float

out uvec4 fragOutput0;

void main()
{
  ivec3 dims = probePoints;
  ivec2 ij = ivec2(floor(texCoord * vec2(dims.xy - ivec2(1))));
  uint count = 0u;
  for (int k = 0; k < dims.z - 1; ++k)
  {
    float vmin = 1.0e30;
    float vmax = -1.0e30;
    for (int c = 0; c < 8; ++c)
    {
      ivec3 p = ivec3(ij.x + (c & 1), ij.y + ((c >> 1) & 1), k + ((c >> 2) & 1));
      ivec4 quad = texelFetch(probeVolume, ivec3(p.x >> 2, p.yz), 0);
      int x = p.x & 3;
      float v = float(x < 2 ? (x == 0 ? quad.x : quad.y) : (x == 2 ? quad.z : quad.w));
      vmin = min(vmin, v);
      vmax = max(vmax, v);
    }
    if (vmin < isovalue && isovalue <= vmax)
    {
      count += 1u;
    }
  }
  fragOutput0 = uvec4(count, 0u, 0u, 0u);
}
