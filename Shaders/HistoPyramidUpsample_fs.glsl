// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidUpsample_fs.glsl: the second pass of a frame drawn at an image
// sample distance above 1 (mediso::IsosurfaceRendererGL, interactive frames).
// The first pass drew the surfaces into the renderer's reduced target
// (reducedSize pixels for the whole viewport, cleared to no surface): colour
// (premultiplied for translucent surfaces) and the window depth of each
// pixel's nearest hit. Drawn over the viewport into the host's framebuffer
// with the host's depth test, each window pixel takes the reduced pixel it
// falls in (nearest: colour and depth stay one hit's, so the surface still
// hides what lies behind it and other geometry in front still hides it).
// The renderer sets the blending: none for opaque surfaces, premultiplied
// "over" for translucent ones.

uniform sampler2D reducedColor;
#ifdef MEDISO_GLSL_ES
uniform highp sampler2D reducedDepth;
#else
uniform sampler2D reducedDepth;
#endif
uniform vec4 viewport;      // the host's viewport: x, y, width, height in pixels
uniform ivec2 reducedSize;  // the reduced target's pixels

MEDISO_OUTPUT(0) vec4 fragOutput0;

void main()
{
  vec2 position = (gl_FragCoord.xy - viewport.xy) / viewport.zw;
  ivec2 texel = clamp(ivec2(position * vec2(reducedSize)), ivec2(0), reducedSize - 1);
  vec4 color = texelFetch(reducedColor, texel, 0);
  if (color.a == 0.0)
  {
    discard; // no surface in this pixel
  }
  fragOutput0 = color;
  gl_FragDepth = texelFetch(reducedDepth, texel, 0).r;
}
