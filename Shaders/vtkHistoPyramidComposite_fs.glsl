//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidComposite_fs.glsl: second pass of the first-hit drawing of
// vtkHistoPyramidIsoMapper (see vtkHistoPyramidIsoMapper::SetFirstHitPass).
// The first pass left, in the mapper's own viewport-sized buffers, the colour
// of the nearest hit of each pixel (alpha 1 where there is one) and its
// exact window depth. Drawn over the viewport into the scene's framebuffer
// with the scene's depth test, this writes them as the one-pass drawing
// would have: other geometry in front hides the surface, and the surface's
// exact depth hides what lies behind it.

//VTK::Output::Dec

in vec2 texCoord; // [0, 1]^2 over the viewport (vtkOpenGLQuadHelper)
uniform sampler2D hitColor;
uniform sampler2D hitDepth;

void main()
{
  // This pixel's texel (texCoord is at the pixel's centre).
  ivec2 texel = ivec2(texCoord * vec2(textureSize(hitColor, 0)));
  vec4 color = texelFetch(hitColor, texel, 0);
  if (color.a == 0.0)
  {
    discard; // no hit in this pixel
  }
  gl_FragData[0] = vec4(color.rgb, 1.0);
  gl_FragDepth = texelFetch(hitDepth, texel, 0).r;
}
