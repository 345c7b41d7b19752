// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidComposite_fs.glsl: second pass of the first-hit drawing of
// mediso::IsosurfaceRendererGL. The first pass left, in the renderer's own
// buffers, the colour of the nearest hit of each pixel (alpha 1 where there
// is one) and its window depth (a float, or its bits on OpenGL ES), for the rectangle of
// window pixels the volume can cover (buffer texel (0, 0) is its first
// pixel). Drawn over that rectangle (the viewport is set to it) into the
// host's framebuffer with the host's depth test, this writes them as the
// one-pass drawing would have: other geometry in front hides the surface,
// and the surface's depth hides what lies behind it.

uniform sampler2D hitColor;
#ifdef MEDISO_GLSL_ES
uniform highp usampler2D hitDepth;
#else
uniform sampler2D hitDepth;
#endif
uniform ivec2 hitOrigin; // the window pixel of buffer texel (0, 0)

MEDISO_OUTPUT(0) vec4 fragOutput0;

void main()
{
  ivec2 texel = ivec2(gl_FragCoord.xy) - hitOrigin;
  vec4 color = texelFetch(hitColor, texel, 0);
  if (color.a == 0.0)
  {
    discard; // no hit in this pixel
  }
  fragOutput0 = vec4(color.rgb, 1.0);
#ifdef MEDISO_GLSL_ES
  gl_FragDepth = uintBitsToFloat(texelFetch(hitDepth, texel, 0).r);
#else
  gl_FragDepth = texelFetch(hitDepth, texel, 0).r;
#endif
}
