//MEDISO::FragmentExtensions
// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidIso_fs.glsl: fragment stage of the isosurface drawing program
// (mediso::IsosurfaceRendererGL).
// Ray-casts the exact trilinear isosurface inside one cell (the cell
// rasterisation of Liu, Clapworthy & Dong 2009; seed paper, section 4.1).
//
// 1. The ray. The fragment's window position is unprojected at the depth of
//    the footprint (see the vertex stage) to a point x on its ray. The eye is
//    homogeneous in cell-index space (w = 1 perspective: its position; w = 0
//    parallel: the direction towards the viewer), so the ray has direction
//    x w - eye.xyz in both projections. It is clipped to the cell box (and,
//    in perspective, to start at the eye, at t = -1).
// 2. The root. Along the ray, the trilinear interpolant minus the isovalue
//    is a cubic in t. Its derivative's roots split [t0, t1] into at most
//    three monotonic pieces (Marmitt et al., "Fast and accurate ray-voxel
//    intersection techniques for iso-surface ray tracing", VMV 2004); the
//    first piece whose ends differ in sign holds the first root, refined by
//    regula falsi with the Illinois modification (a bracket is always kept,
//    so there is no divergence near tangents or at cell faces). No sign
//    change: the ray misses, the fragment is discarded.
// 3. Shading: Phong with the gradient at the hit (the corners' central
//    differences, interpolated trilinearly: continuous across cells; turned
//    to face the viewer: isosurfaces are two-sided), the volume property's ambient,
//    diffuse, specular and specular power, and the renderer's lights.
// 4. Depth: gl_FragDepth from the hit point, so the surface composites
//    exactly with polygonal geometry in the same scene. Where the context
//    has GL_ARB_conservative_depth (or OpenGL 4.2), the renderer declares
//    gl_FragDepth depth_greater in place of the FragmentExtensions hook
//    above: the hit lies behind the footprint's depth, so the depth test
//    may run before this shader, and with the cells drawn front to back the
//    cells hidden behind a surface already drawn cost no ray casting (the
//    paper's reason for sorting).
//
// Clipping planes (MEDISO_CLIP_PLANES, their number): the kept part of the
// volume is the intersection of the planes' kept half-spaces, which is
// convex, so the ray's piece in the cell keeps one interval [t0, t1] and the
// root search runs only there. A ray that enters the kept part at a plane
// finds the surface behind it: the cut is seen through, left open.
//
// Variants: the renderer defines MEDISO_POINT_FOOTPRINT (see the vertex
// stage), MEDISO_TRANSLUCENT (any isovalue with opacity < 1), MEDISO_LIGHTS (the
// number of lights) and MEDISO_ISOVALUES (the number of isovalues, for the
// translucent loop) and compiles each combination apart: a software
// rasteriser runs every branch under SIMD masks, so code for another mode or
// a loop with a uniform bound costs every fragment.
//
// Several opaque isovalues in the first-hit pass (MEDISO_NEAREST): one
// primitive per cell, as in translucent mode, and this stage takes the
// nearest of the first roots of the cell's crossing isovalues. With the
// cells in front-to-back order, the first hit in drawing order is then the
// nearest hit of any isovalue (with one primitive per cell-isovalue pair, a
// cell's primitives come in isovalue order, not depth order).
//
// Translucent mode (MEDISO_TRANSLUCENT): the renderer draws the
// cells back to front and only one primitive per cell; this fragment takes
// the hits of every crossing isovalue along its piece of ray in order of t
// (a merge of the isovalues' hit sequences) and composites them front to
// back, writing premultiplied colour (the
// blend is ONE, ONE_MINUS_SRC_ALPHA). Cells never overlap, so ordered cells
// and ordered hits inside each cell give the exact compositing order: an
// opaque bone behind translucent skin, in one pass.

// Outputs: fragOutput0, the colour (premultiplied in translucent mode); in
// the first-hit pass (MEDISO_FIRST_HIT) also fragOutput1, the hit's window
// depth, exactly, in place of gl_FragDepth: the float itself into an R32F
// target on desktop OpenGL, its bits into an R32UI target on OpenGL ES 3.0
// (where float targets need an extension).
MEDISO_OUTPUT(0) vec4 fragOutput0;
#ifdef MEDISO_FIRST_HIT
#ifdef MEDISO_GLSL_ES
MEDISO_OUTPUT(1) uvec4 fragOutput1;
#else
MEDISO_OUTPUT(1) vec4 fragOutput1;
#endif
#endif

flat in ivec4 vCellMask;    // the cell (xyz) and its crossing isovalues (w)
flat in vec4 vLook;         // colour (rgb) and value (w) of the isovalue drawn
flat in vec4 vLow;          // corner values 0..3
flat in vec4 vHigh;         // corner values 4..7
flat in vec4 vGradients[6]; // the corners' central-difference gradients, 3 floats each
flat in float vNearDepth;   // the footprint's NDC depth
uniform mat4 clipToIndex;
uniform vec4 viewport;      // x, y, width, height in pixels

#define gCell vCellMask.xyz
#define gMask vCellMask.w
#define gLook vLook
#define gLow vLow
#define gHigh vHigh

// A point on this fragment's ray: its window position unprojected at the
// footprint's depth (close to the cell).
vec3 rayPoint()
{
  vec2 ndc = 2.0 * (gl_FragCoord.xy - viewport.xy) / viewport.zw - 1.0;
  vec4 p = clipToIndex * vec4(ndc, vNearDepth, 1.0);
  return p.xyz / p.w;
}

uniform vec4 eyeIndex;
uniform mat4 indexToClip;
uniform mat4 indexToView;
uniform mat3 gradientToView;     // inverse transpose of indexToView's linear part
uniform int parallelProjection;
uniform float isovalues[8];      // bit t of gMask: isovalues[t]
uniform vec4 isoColors[8];       // rgb, opacity
uniform float ambient;
uniform float diffuse;
uniform float specular;
uniform float specularPower;
uniform vec3 lightDirections[6]; // view space, from the surface towards the light
uniform vec3 lightColors[6];
#ifdef MEDISO_CLIP_PLANES
uniform vec4 clipPlanes[MEDISO_CLIP_PLANES]; // index space; a p + w >= 0 is kept
#endif

// The corners' central-difference gradients, interpolated trilinearly.
vec3 gradient(vec3 p)
{
  vec3 g0 = vGradients[0].xyz;
  vec3 g1 = vec3(vGradients[0].w, vGradients[1].xy);
  vec3 g2 = vec3(vGradients[1].zw, vGradients[2].x);
  vec3 g3 = vGradients[2].yzw;
  vec3 g4 = vGradients[3].xyz;
  vec3 g5 = vec3(vGradients[3].w, vGradients[4].xy);
  vec3 g6 = vec3(vGradients[4].zw, vGradients[5].x);
  vec3 g7 = vGradients[5].yzw;
  vec3 y0z0 = mix(g0, g1, p.x);
  vec3 y1z0 = mix(g2, g3, p.x);
  vec3 y0z1 = mix(g4, g5, p.x);
  vec3 y1z1 = mix(g6, g7, p.x);
  return mix(mix(y0z0, y1z0, p.y), mix(y0z1, y1z1, p.y), p.z);
}

// Coefficients of f(t) = trilinear(o + t d) - iso = ((a t + b) t + c) t + e.
// The interpolant in monomial form, m0 + m1 x + m2 y + m3 z + m4 xy + m5 yz
// + m6 xz + m7 xyz, makes them a few products per fragment.
vec4 cubic(vec3 o, vec3 d, float iso)
{
  float c000 = gLow.x, c100 = gLow.y, c010 = gLow.z, c110 = gLow.w;
  float c001 = gHigh.x, c101 = gHigh.y, c011 = gHigh.z, c111 = gHigh.w;
  float m1 = c100 - c000;
  float m2 = c010 - c000;
  float m3 = c001 - c000;
  float m4 = c110 - c100 - c010 + c000;
  float m5 = c011 - c010 - c001 + c000;
  float m6 = c101 - c100 - c001 + c000;
  float m7 = c111 - c110 - c101 - c011 + c100 + c010 + c001 - c000;
  // Gradient of the interpolant at o, and its second-order terms along d.
  vec3 g = vec3(m1 + m4 * o.y + m6 * o.z + m7 * o.y * o.z,
                m2 + m4 * o.x + m5 * o.z + m7 * o.x * o.z,
                m3 + m5 * o.y + m6 * o.x + m7 * o.x * o.y);
  float value = c000 - iso + m1 * o.x + m2 * o.y + m3 * o.z + m4 * o.x * o.y + m5 * o.y * o.z +
    m6 * o.x * o.z + m7 * o.x * o.y * o.z;
  float quadratic = m4 * d.x * d.y + m5 * d.y * d.z + m6 * d.x * d.z +
    m7 * (o.x * d.y * d.z + o.y * d.x * d.z + o.z * d.x * d.y);
  return vec4(m7 * d.x * d.y * d.z, quadratic, dot(g, d), value);
}

float evalCubic(vec4 k, float t)
{
  return ((k.x * t + k.y) * t + k.z) * t + k.w;
}

// The root in [ta, tb], where f(ta) and f(tb) differ in sign, to within
// `tolerance` in t (1e-4 voxel: far below what a pixel or the depth buffer
// resolves; fragments run in SIMD groups, so every iteration saved counts).
float refine(vec4 k, float ta, float tb, float fa, float fb, float tolerance)
{
  int side = 0;
  for (int it = 0; it < 16; ++it)
  {
    float t = (fa * tb - fb * ta) / (fa - fb);
    float ft = evalCubic(k, t);
    if (ft * fb > 0.0)
    {
      tb = t;
      fb = ft;
      if (side == -1)
      {
        fa *= 0.5;
      }
      side = -1;
    }
    else if (ft * fa > 0.0)
    {
      ta = t;
      fa = ft;
      if (side == 1)
      {
        fb *= 0.5;
      }
      side = 1;
    }
    else
    {
      return t;
    }
    if (abs(tb - ta) <= tolerance)
    {
      break;
    }
  }
  return (fa * tb - fb * ta) / (fa - fb);
}

// The roots r0 <= r1 of f' (3a t^2 + 2b t + c), each t1 where there is none.
void derivativeRoots(vec4 k, float t1, out float r0, out float r1)
{
  float a = 3.0 * k.x, b = 2.0 * k.y, c = k.z;
  r0 = t1;
  r1 = t1;
  float scale = abs(a) + abs(b) + abs(c);
  if (abs(a) > 1e-7 * scale)
  {
    float disc = b * b - 4.0 * a * c;
    if (disc > 0.0)
    {
      float q = b == 0.0 ? -0.5 * sqrt(disc) : -0.5 * (b + sign(b) * sqrt(disc));
      float x0 = q / a;
      float x1 = q != 0.0 ? c / q : x0;
      r0 = min(x0, x1);
      r1 = max(x0, x1);
    }
  }
  else if (abs(b) > 0.0)
  {
    r0 = -c / b;
  }
}

// The first root of f on [t0, t1], if any: f' has at most two roots, which
// split [t0, t1] into at most three monotonic pieces; the first piece whose
// ends differ in sign holds the first root. Written without arrays or
// data-dependent loops over the pieces (a software rasteriser runs fragments
// in SIMD groups, where indexing a local array with a varying index becomes
// per-lane memory traffic).
bool firstRoot(vec4 k, float t0, float t1, float tolerance, out float hit)
{
  float r0, r1;
  derivativeRoots(k, t1, r0, r1);
  float s1 = clamp(r0, t0, t1);
  float s2 = clamp(r1, s1, t1);
  float f0 = evalCubic(k, t0);
  float f1 = evalCubic(k, s1);
  float f2 = evalCubic(k, s2);
  float f3 = evalCubic(k, t1);
  float ta, tb, fa, fb;
  if (f0 * f1 <= 0.0)
  {
    ta = t0; tb = s1; fa = f0; fb = f1;
  }
  else if (f1 * f2 <= 0.0)
  {
    ta = s1; tb = s2; fa = f1; fb = f2;
  }
  else if (f2 * f3 <= 0.0)
  {
    ta = s2; tb = t1; fa = f2; fb = f3;
  }
  else
  {
    return false;
  }
  hit = fa == 0.0 ? ta : (fb == 0.0 ? tb : refine(k, ta, tb, fa, fb, tolerance));
  return true;
}

vec3 shade(vec3 p, vec3 color)
{
  vec3 hit = vec3(gCell) + p;
  vec3 n = gradientToView * gradient(p);
  float len = length(n);
  n = len > 0.0 ? n / len : vec3(0.0, 0.0, 1.0);
  vec3 toViewer = parallelProjection == 1 ? vec3(0.0, 0.0, 1.0)
                                          : -normalize((indexToView * vec4(hit, 1.0)).xyz);
  if (dot(n, toViewer) < 0.0)
  {
    n = -n;
  }
  vec3 result = ambient * color;
  for (int l = 0; l < MEDISO_LIGHTS; ++l)
  {
    vec3 toLight = lightDirections[l];
    float lambert = max(dot(n, toLight), 0.0);
    result += diffuse * lambert * color * lightColors[l];
    if (lambert > 0.0 && specular > 0.0)
    {
      vec3 r = reflect(-toLight, n);
      result += specular * pow(max(dot(r, toViewer), 0.0), specularPower) * lightColors[l];
    }
  }
  return result;
}

#ifdef MEDISO_TRANSLUCENT
// Isovalue t's next hit, t in 0..7, kept in two vec4s (lo: 0..3, hi: 4..7)
// rather than an array (see firstRoot()).
void setNext(int t, float value, inout vec4 lo, inout vec4 hi)
{
  lo = mix(lo, vec4(value), equal(ivec4(0, 1, 2, 3), ivec4(t)));
  hi = mix(hi, vec4(value), equal(ivec4(4, 5, 6, 7), ivec4(t)));
}
#endif

float depthOf(vec3 p)
{
  vec4 clip = indexToClip * vec4(vec3(gCell) + p, 1.0);
  float ndc = clip.z / clip.w;
  return 0.5 * (gl_DepthRange.diff * ndc + gl_DepthRange.near + gl_DepthRange.far);
}

void main()
{
  // 1. The ray in the cell's local coordinates: p(t) = o + t d, cell [0, 1]^3.
  vec3 position = rayPoint();
  vec3 o = position - vec3(gCell);
  vec3 d = position * eyeIndex.w - eyeIndex.xyz;
  // A ray parallel to a face of the cell (an axis-aligned parallel view)
  // that runs in that face, up to the rounding of the point unprojected
  // from the window, belongs to the cell: inside the volume a neighbour would
  // take it, but on the volume's own faces none does.
  float rounding = 1e-5 + 1e-6 * max(max(abs(position.x), abs(position.y)), abs(position.z));
  bvec3 inFace = lessThanEqual(abs(o - 0.5), vec3(0.5 + rounding));
  o = mix(o, clamp(o, 0.0, 1.0), bvec3(inFace.x && d.x == 0.0, inFace.y && d.y == 0.0,
                                       inFace.z && d.z == 0.0));
  vec3 safe = mix(d, vec3(1e-30), equal(d, vec3(0.0)));
  vec3 ta = -o / safe;
  vec3 tb = (1.0 - o) / safe;
  vec3 tlo = min(ta, tb);
  vec3 thi = max(ta, tb);
  float t0 = max(max(tlo.x, tlo.y), tlo.z);
  float t1 = min(min(thi.x, thi.y), thi.z);
  if (parallelProjection == 0)
  {
    t0 = max(t0, -1.0); // the eye
  }
#ifdef MEDISO_CLIP_PLANES
  // Each plane's value along the ray is linear in t: the kept half-space
  // bounds t from below where the ray goes towards it, from above where it
  // leaves, and keeps all or nothing of a ray parallel to the plane.
  vec3 start = vec3(gCell) + o;
  for (int i = 0; i < MEDISO_CLIP_PLANES; ++i)
  {
    float along = dot(clipPlanes[i].xyz, d);
    float at = dot(clipPlanes[i].xyz, start) + clipPlanes[i].w;
    float crossing = -at / (along == 0.0 ? 1.0 : along);
    t0 = along > 0.0 ? max(t0, crossing) : t0;
    t1 = along < 0.0 ? min(t1, crossing) : (along == 0.0 && at < 0.0 ? -3.0e38 : t1);
  }
#endif
  if (!(t0 <= t1))
  {
    discard;
  }
  float tolerance = 1e-4 / max(length(d), 1e-30);

#if defined(MEDISO_NEAREST)
  // 2. Several opaque isovalues, one primitive per cell (the first-hit
  //    pass): the nearest of the first roots of the cell's crossing
  //    isovalues, in that isovalue's colour.
  float hitT = 3.0e38;
  int nearest = -1;
  for (int t = 0; t < MEDISO_ISOVALUES; ++t)
  {
    float root;
    if (((gMask >> t) & 1) == 1 && firstRoot(cubic(o, d, isovalues[t]), t0, t1, tolerance, root) &&
      root < hitT)
    {
      hitT = root;
      nearest = t;
    }
  }
  if (nearest < 0)
  {
    discard;
  }
  vec3 color = isoColors[nearest].rgb;
#elif !defined(MEDISO_TRANSLUCENT)
  // 2. First root of the one isovalue of this primitive (gLook: its colour
  //    and value, looked up once per cell by the vertex stage).
  vec4 k = cubic(o, d, gLook.w);
  float hitT;
  if (!firstRoot(k, t0, t1, tolerance, hitT))
  {
    discard;
  }
  vec3 color = gLook.rgb;
#endif
#ifndef MEDISO_TRANSLUCENT
  vec3 p = clamp(o + hitT * d, 0.0, 1.0);
  fragOutput0 = vec4(shade(p, color), 1.0);
#ifdef MEDISO_FIRST_HIT
  // First-hit pass: the depth test ran before this stage, on the
  // footprint's constant depth (see the vertex stage): this pixel had no hit
  // yet. The depth goes to the renderer's buffer; the composite pass writes it.
#ifdef MEDISO_GLSL_ES
  fragOutput1 = uvec4(floatBitsToUint(depthOf(p)), 0u, 0u, 0u);
#else
  fragOutput1 = vec4(depthOf(p), 0.0, 0.0, 1.0);
#endif
#else
  gl_FragDepth = depthOf(p);
#endif
#else
  // Translucent: every hit of every crossing isovalue, composited front to
  // back as a merge of the isovalues' hit sequences. Each crossing isovalue
  // keeps its next hit (the first root at or after its own start); the
  // nearest of them is composited and only that isovalue looks for its next
  // one, from just past the hit (2 tolerances: the refined root is within
  // one of the true one, so a pair of roots closer than that, a ray grazing
  // the surface, counts once). No arrays (see firstRoot()): the per-isovalue
  // state lives in two vec4s, and MEDISO_ISOVALUES is a constant.
  const float none = 3.0e38;
  vec4 nextLo = vec4(none);
  vec4 nextHi = vec4(none);
  for (int t = 0; t < MEDISO_ISOVALUES; ++t)
  {
    float root;
    if (((gMask >> t) & 1) == 1 && firstRoot(cubic(o, d, isovalues[t]), t0, t1, tolerance, root))
    {
      setNext(t, root, nextLo, nextHi);
    }
  }
  vec4 sum = vec4(0.0);
  float firstHit = none;
  // A cubic has at most 3 roots per isovalue.
  for (int h = 0; h < 3 * MEDISO_ISOVALUES && sum.a < 0.998; ++h)
  {
    // The nearest next hit; on a tie, the lower isovalue first.
    float best = none;
    int iso = -1;
    for (int t = 0; t < MEDISO_ISOVALUES; ++t)
    {
      float next = t < 4 ? nextLo[t] : nextHi[t - 4];
      if (next < best)
      {
        best = next;
        iso = t;
      }
    }
    if (iso < 0)
    {
      break;
    }
    firstHit = min(firstHit, best);
    vec3 p = clamp(o + best * d, 0.0, 1.0);
    vec4 c = isoColors[iso];
    sum += (1.0 - sum.a) * c.a * vec4(shade(p, c.rgb), 1.0);
    float from = best + 2.0 * tolerance;
    float root;
    float next = none;
    if (from <= t1 && firstRoot(cubic(o, d, isovalues[iso]), from, t1, tolerance, root))
    {
      next = root;
    }
    setNext(iso, next, nextLo, nextHi);
  }
  if (firstHit == none)
  {
    discard;
  }
  fragOutput0 = sum;
  gl_FragDepth = depthOf(clamp(o + firstHit * d, 0.0, 1.0));
#endif
}
