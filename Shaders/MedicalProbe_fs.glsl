// SPDX-License-Identifier: BSD-3-Clause
//
// MedicalProbe_fs.glsl: fragment stage of the GPU core's functional probe
// (mediso::ProbeGL). It does, on a tiny volume, exactly what the first level
// of the HistoPyramid does: read an int16 volume stored as an RGBA16I 3D
// texture (4 points to a texel along x, as the core stores a volume) with
// texelFetch, classify cells against an isovalue and write an unsigned
// integer count per fragment into an R32UI render target.
//
// Drawn as one full-screen triangle over a target of (nx - 1) x (ny - 1)
// texels: fragment (i, j) writes the number of ACTIVE cells in the cell
// column (i, j, k = 0 .. nz - 2). A cell is active when its eight corner
// values straddle the isovalue, min < isovalue <= max.

uniform highp isampler3D probeVolume; // RGBA16I, texelFetch only
uniform ivec3 probePoints;            // points per axis (texel (i, j, k) holds points 4i .. 4i + 3)
uniform float isovalue;               // int16 values are exact in float

MEDISO_OUTPUT(0) uvec4 fragOutput0;

void main()
{
  ivec3 dims = probePoints;
  ivec2 ij = ivec2(gl_FragCoord.xy);
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
