// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidCoverage_fs.glsl: one level of the first-hit pass's coverage
// pyramid (mediso::IsosurfaceRendererGL, drawn with
// HistoPyramidFullScreen_vs.glsl into level l of an R8 texture). A texel of
// level l is 1 where every one of the 2^(l + 1) x 2^(l + 1) hit-buffer pixels
// of its block holds a hit, else 0: the minimum of its 2x2 texels in the
// level below, read from the hit colour's alpha (level 0: alpha is 1 exactly
// where a hit was written) or from that level's red. Texels beyond the level
// below count as no hit, so a block that reaches past the buffers is never
// covered. The vertex stage then drops a point whose pixels all lie in
// covered blocks (pointCovered() in HistoPyramidIso_vs.glsl).

uniform sampler2D source;
uniform ivec2 sourceSize;
uniform int fromHits; // 1: source is the hit colour (alpha); 0: the level below (red)

MEDISO_OUTPUT(0) vec4 fragOutput0;

void main()
{
  ivec2 first = 2 * ivec2(gl_FragCoord.xy);
  float covered = 1.0;
  for (int i = 0; i < 4; ++i)
  {
    ivec2 t = first + ivec2(i & 1, i >> 1);
    vec4 texel = texelFetch(source, min(t, sourceSize - 1), 0);
    float hit = fromHits == 1 ? texel.a : texel.r;
    covered = min(covered, all(lessThan(t, sourceSize)) ? hit : 0.0);
  }
  fragOutput0 = vec4(covered);
}
