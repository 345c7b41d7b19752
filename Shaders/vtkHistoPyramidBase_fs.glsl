//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidBase_fs.glsl: base level of the GPU HistoPyramid
// (vtkOpenGLHistoPyramid). Drawn as one full-screen quad per z-slice of the
// level-0 GL_R32UI 3D texture: fragment (i, j) of slice k is cell (i, j, k)
// and writes how many isovalues cross the cell, min < iso <= max over its
// eight corners (0 for a cell with a NaN corner, and for the padding cells
// beyond the real cell grid).
//
// The value type of the volume texture is chosen before the program is
// built: vtkOpenGLHistoPyramid replaces the ValueType hook below with
// #defines of VALUE_SAMPLER (isampler3D, usampler3D or sampler3D),
// VALUE_TYPE (int, uint or float) and, for float data, VALUE_IS_FLOAT.
// The isovalues arrive as thresholds of that same type, computed on the CPU
// so that "min < t && t <= max" here gives exactly "min < iso && iso <= max"
// in double precision (ceil(iso) for integer data, the smallest float not
// below iso for float data); isovalues that can never cross are dropped.
//
// GLSL 1.50 only. Integer output: no "//VTK::Output::Dec" line, the shader
// declares its own uvec4 output (see vtkMedicalProbe_fs.glsl for why).
// The cell index comes from texCoord (which also keeps the quad helper's
// texCoordIn attribute alive): fragment centres sit at (i + 0.5) / width.

//VTK::HistoPyramidValueType::Dec

in vec2 texCoord;

uniform VALUE_SAMPLER volume;        // point values, texelFetch only
uniform VALUE_TYPE thresholds[8];    // see above
uniform int numberOfThresholds;      // 0 .. 8
uniform ivec3 cellDimensions;        // real cells per axis (points - 1)
uniform ivec2 sliceSize;             // level-0 size in x and y (powers of two)
uniform int slice;                   // z of the slice being written

out uvec4 fragOutput0;

void main()
{
  ivec3 cell = ivec3(ivec2(floor(texCoord * vec2(sliceSize))), slice);
  uint count = 0u;
  if (all(lessThan(cell, cellDimensions)))
  {
    VALUE_TYPE lo = texelFetch(volume, cell, 0).r;
    VALUE_TYPE hi = lo;
#ifdef VALUE_IS_FLOAT
    bool nan = isnan(lo);
#endif
    for (int c = 1; c < 8; ++c)
    {
      VALUE_TYPE v = texelFetch(volume, cell + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1), 0).r;
#ifdef VALUE_IS_FLOAT
      nan = nan || isnan(v);
#endif
      lo = min(lo, v);
      hi = max(hi, v);
    }
#ifdef VALUE_IS_FLOAT
    if (!nan)
#endif
    {
      for (int t = 0; t < numberOfThresholds; ++t)
      {
        if (lo < thresholds[t] && thresholds[t] <= hi)
        {
          count += 1u;
        }
      }
    }
  }
  fragOutput0 = uvec4(count, 0u, 0u, 0u);
}
