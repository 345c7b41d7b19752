//VTK::System::Dec
// SPDX-License-Identifier: BSD-3-Clause
//
// vtkHistoPyramidComposite_fs.glsl: second pass of the first-hit drawing of
// vtkHistoPyramidIsoMapper (see vtkHistoPyramidIsoMapper::SetFirstHitPass).
// The first pass left, in the mapper's own buffers, the colour of the
// nearest hit of each pixel (alpha 1 where there is one) and its exact window
// depth, for the rectangle of window pixels the volume can cover (buffer
// texel (0, 0) is its first pixel). Drawn over that rectangle (the mapper
// sets the viewport to it) into the scene's framebuffer with the scene's
// depth test, this writes them as the one-pass drawing would have: other
// geometry in front hides the surface, and the surface's exact depth hides
// what lies behind it.

//VTK::Output::Dec

in vec2 texCoord; // [0, 1]^2 over those pixels (vtkOpenGLQuadHelper)
uniform sampler2D hitColor;
uniform sampler2D hitDepth;
uniform vec2 hitExtent; // their width and height (the buffers may be larger)

void main()
{
  // This pixel's texel (texCoord is at the pixel's centre).
  ivec2 texel = ivec2(texCoord * hitExtent);
  vec4 color = texelFetch(hitColor, texel, 0);
  if (color.a == 0.0)
  {
    discard; // no hit in this pixel
  }
  gl_FragData[0] = vec4(color.rgb, 1.0);
  gl_FragDepth = texelFetch(hitDepth, texel, 0).r;
}
