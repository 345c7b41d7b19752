// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidIso_vs.glsl: vertex stage of the isosurface drawing program
// (mediso::IsosurfaceRendererGL). It draws the pyramid's total of primitives
// with no vertex attributes and one draw call (no per-cell CPU work):
// primitive number MEDISO_PRIMITIVE walks down the HistoPyramid of
// mediso::HistoPyramidGL to find its cell and which of the cell's crossing
// isovalues it draws (Ziegler et al. 2006; the cell-rasterisation scheme of
// Liu, Clapworthy & Dong 2009, section 4.1 of the seed paper).
//
// Front-to-back order without sorting: at every node the children are
// visited nearest first, the near half along each axis being the one on the
// eye's side of the node's split plane (the layout and order of
// mediso::HistoPyramid::Traverse, tested on the CPU). Primitive k is then
// never in front of primitive k + 1 along a ray from the eye, so early depth
// rejection works with no per-frame sort; backToFront = 1 reverses the order
// for translucent compositing. The eye is homogeneous, in cell-index space:
// w = 1 for a perspective camera (its position), w = 0 for a parallel one
// (the direction towards the viewer), so both projections share one test.
//
// The levels are separate 2D atlases (each level has its own size and
// format; each packed 2x2 nodes to an RGBA texel, slices side by side, see
// descend()), and GLSL cannot index an array of samplers with a variable:
// the renderer puts one uniform per stored level in place of the
// HistoPyramidLevels hook and one descend() call per level, with that
// level's constant factors and atlas shifts, in place of the
// HistoPyramidDescent hook. Level 0 is not stored: the
// last step recounts the up-to-8 cells of the level-1 node from their <= 27
// corner values, which then give the cell's corners and half of their
// gradient neighbours as well (cellCorners()): 16 + 18 + 12 texel fetches
// per vertex on the 512x512x216 CT (the volume holds 4 points to a texel
// along x, so a row of the node's 3 points takes 2 fetches at most). With
// one isovalue (MEDISO_CHILD_MASKS) level 1 holds each node's child mask
// instead of its count, and the last step down reads it with the counts
// (descendToMasks()): the recount's crossing tests are skipped, the node's
// points are still read for the corners.
//
// Footprint. This stage makes the cell's footprint itself, over the
// bounding rectangle, on screen, of the box that holds the surface in the
// cell (see surfaceBox(); often much smaller than the cell: on a software
// rasteriser every fragment costs a full ray cast, hit or miss), at the
// depth of the box's nearest point (the hit lies inside the box, so it is
// never in front of the footprint: early depth rejection stays valid).
// - MEDISO_POINT_FOOTPRINT (the renderer chooses it when every cell of the
//   volume projects to fewer pixels than the largest point size and the
//   volume lies wholly beyond the near plane): one point sprite per
//   primitive, as wide as the rectangle's longer side (gl_VertexID is the
//   primitive).
// - Otherwise (close zooms, the eye in or near the volume): a quad, drawn as
//   an instanced triangle strip of 4 vertices (gl_InstanceID is the
//   primitive), over the rectangle of the box cut by the near plane, so no
//   size limit applies and a cell that reaches behind the eye is covered
//   where it is visible. Each of the 4 vertices walks the pyramid, which
//   costs 4 times the vertex work of a point; no geometry stage exists in
//   OpenGL ES 3.0.

//MEDISO::HistoPyramidCommon

//MEDISO::HistoPyramidLevels

#ifdef MEDISO_POINT_FOOTPRINT
#define MEDISO_PRIMITIVE gl_VertexID
#else
#define MEDISO_PRIMITIVE gl_InstanceID
#endif

uniform vec4 eyeIndex;       // eye, homogeneous, in cell-index space
uniform int backToFront;     // 0: nearest cells first; 1: farthest first
uniform int oneRankPerCell;  // 1: only the first primitive of a cell is drawn
uniform ivec3 firstFactor;   // level-1 node size in cells (1 or 2 per axis)
uniform float isovalues[8];  // the fragment stage's isovalues and looks
uniform vec4 isoColors[8];

uniform mat4 indexToClip;    // cell-index space to clip coordinates
uniform vec2 viewportSize;   // pixels
uniform float pointMargin;   // pixels added around each footprint
#ifdef MEDISO_POINT_FOOTPRINT
uniform float maxPointSize;  // the largest point size
#endif

#ifdef MEDISO_HIT_CULL
// Hidden points dropped in the first-hit pass, which the renderer draws in
// ranges of the primitives (front to back) with the coverage pyramid of the
// hits drawn so far made after each (HistoPyramidCoverage_fs.glsl).
uniform sampler2D hitCoverage; // level l: 1 where a block of 2^(l + 1) buffer pixels all hold a hit
uniform int coverageLevels;
uniform vec2 coverageOrigin;   // this viewport's pixel (0, 0) in the hit buffers
uniform int cullHidden;        // 0 in the first range (no hit drawn yet)

// Whether every pixel a point of `size` pixels centred at NDC `ndc` can
// cover already holds a hit. Then the first-hit pass's depth test (every
// primitive at one depth, GL_LESS: a pixel's first hit rejects every later
// fragment) would reject all of its fragments, so dropping the point leaves
// the image and the depth exactly as they were, and spares its setup,
// binning and fragments. Only the pixels whose rays can hit the surface in
// the cell matter (any other fragment finds no root and writes nothing):
// they lie in the projected surface box, which the square of the point's
// size about its centre holds with the footprint's margin to spare, so a
// rasteriser that rounds the size up adds only pixels that cannot hit. The
// square is widened by a hundredth of a pixel for the rounding of the
// window transform. The pixels whose centres it holds lie in at most 2x2
// blocks of the lowest level whose blocks are at least as wide as it, and
// all 4 must be covered; blocks beyond the buffers never are.
bool pointCovered(vec2 ndc, float size)
{
  vec2 centre = (0.5 * ndc + 0.5) * viewportSize + coverageOrigin;
  float radius = 0.5 * max(size, 1.0) + 0.01;
  ivec2 first = ivec2(ceil(centre - radius - 0.5));
  ivec2 last = ivec2(floor(centre + radius - 0.5));
  if (any(lessThan(first, ivec2(0))))
  {
    return false;
  }
  int span = max(max(last.x - first.x, last.y - first.y) + 1, 1);
  int level = 0;
  for (int k = 0; k < 14; ++k) // blocks of 2^(level + 1) >= span; 14 levels: 32768 pixels
  {
    level += (2 << level) < span ? 1 : 0;
  }
  if (level >= coverageLevels)
  {
    return false;
  }
  ivec2 b0 = first >> (level + 1);
  ivec2 b1 = last >> (level + 1);
  if (any(greaterThanEqual(b1, textureSize(hitCoverage, level))))
  {
    return false;
  }
  float covered = min(
    min(texelFetch(hitCoverage, b0, level).r, texelFetch(hitCoverage, ivec2(b1.x, b0.y), level).r),
    min(texelFetch(hitCoverage, ivec2(b0.x, b1.y), level).r, texelFetch(hitCoverage, b1, level).r));
  return covered > 0.5;
}
#endif

// The fragment stage's inputs: few slots (OpenGL ES 3.0 promises 15 vec4s).
flat out ivec4 vCellMask;    // the cell (xyz) and its crossing isovalues (w; bit t: threshold t)
flat out vec4 vLook;         // the colour (rgb) and value (w) of the isovalue drawn
flat out vec4 vLow;          // corner values 0..3 (dx + 2 dy + 4 dz)
flat out vec4 vHigh;         // corner values 4..7
flat out vec4 vGradients[6]; // central-difference gradients at corners 0..7, 3 floats each
flat out float vNearDepth;   // NDC depth of the footprint

int vIsovalue;               // the isovalue this primitive draws (-1: none)
vec3 cornerGradients[8];
vec4 walkEye;                // the eye in the texture's cell space (see startWalk())

#ifdef MEDISO_BRICK_POOL
// A brick pool (see HistoPyramidCommon.glsl) is drawn slot by slot, in the
// frame's order of its bricks (nearest first, farthest first for
// translucent surfaces; mediso::IsosurfaceScene chooses it): entry i of
// slotOrder (texel (i % 64, i / 64)) is the first primitive of the i-th
// slot drawn and that slot, the entries' first primitives increasing. A
// primitive finds its entry by a binary search whose first step,
// MEDISO_SLOT_SEARCH, is the power of two from half the pool's slots up (a
// constant: the loop unrolls to log2 of the slots' steps), then walks its
// slot's subtree of the pyramid from the slot's node (the slot's side is a
// power of two, so the slot is one node of level slotShift), with the eye
// moved into the slot, so that the cells come out in the same order as from
// the brick's own pyramid.
uniform usampler2D slotOrder;
uniform int slotOrderCount;

void startWalk(inout uint index, out ivec3 node)
{
  int found = 0;
  for (int step = MEDISO_SLOT_SEARCH; step > 0; step >>= 1)
  {
    int probe = found + step;
    if (probe < slotOrderCount && texelFetch(slotOrder, ivec2(probe & 63, probe >> 6), 0).x <= index)
    {
      found = probe;
    }
  }
  uvec4 entry = texelFetch(slotOrder, ivec2(found & 63, found >> 6), 0);
  index -= entry.x;
  node = ivec3(entry.yzw);
  selectSlot(node);
  walkEye = vec4(eyeIndex.xyz - vec3(slotPlacement - slotOrigin) * eyeIndex.w, eyeIndex.w);
}
#else
void startWalk(inout uint index, out ivec3 node)
{
  node = ivec3(0);
  selectSlot(node);
  walkEye = eyeIndex;
}
#endif

// Children of a node in visiting order: bit a of the returned mask flips
// axis a, so that child (order ^ mask) is the order-th one visited.
int orderMask(ivec3 node, ivec3 factor, vec3 childSpan)
{
  vec3 split = (2.0 * vec3(node) + 1.0) * childSpan;
  bvec3 plusSide = greaterThanEqual(walkEye.xyz - split * walkEye.w, vec3(0.0));
  int mask = (factor.x == 2 && plusSide.x ? 1 : 0) | (factor.y == 2 && plusSide.y ? 2 : 0) |
    (factor.z == 2 && plusSide.z ? 4 : 0);
  if (backToFront == 1)
  {
    mask ^= (factor.x == 2 ? 1 : 0) | (factor.y == 2 ? 2 : 0) | (factor.z == 2 ? 4 : 0);
  }
  return mask;
}

// The child (0..7, dx + 2 dy + 4 dz) whose running sum, in visiting order,
// covers index, given the children's counts (low: dz = 0, high: dz = 1) and
// the order mask (child o ^ mask is the o-th visited); index becomes the
// rank inside that child. Loop-free: the counts are put in visiting order
// by three conditional swaps, and the child is the number of running sums
// not above index.
int pickChild(uvec4 low, uvec4 high, int mask, inout uint index)
{
  // Visiting order: position o holds child o ^ mask.
  bool flipZ = (mask & 4) != 0, flipY = (mask & 2) != 0, flipX = (mask & 1) != 0;
  uvec4 a = flipZ ? high : low;
  uvec4 b = flipZ ? low : high;
  a = flipY ? a.zwxy : a;
  b = flipY ? b.zwxy : b;
  a = flipX ? a.yxwz : a;
  b = flipX ? b.yxwz : b;
  // Inclusive running sums; those not above index are the children passed.
  uvec4 sumA = uvec4(a.x, a.x + a.y, a.x + a.y + a.z, a.x + a.y + a.z + a.w);
  uvec4 sumB = sumA.w + uvec4(b.x, b.x + b.y, b.x + b.y + b.z, b.x + b.y + b.z + b.w);
  uvec4 passedA = uvec4(lessThanEqual(sumA, uvec4(index)));
  uvec4 passedB = uvec4(lessThanEqual(sumB, uvec4(index)));
  uvec4 before = max(sumA * passedA, sumB * passedB);
  int order = int(passedA.x + passedA.y + passedA.z + passedA.w + passedB.x + passedB.y +
    passedB.z + passedB.w);
  index -= max(max(before.x, before.y), max(before.z, before.w));
  return order ^ mask;
}

// The stored values of node's children in the level below: low for dz = 0,
// high for dz = 1 (0 where z has one node).
void childTexels(usampler2D lower, ivec3 factor, ivec3 shifts, ivec3 node, out uvec4 low,
  out uvec4 high)
{
  low = texelFetch(lower, atlasTexel(ivec3(node.xy, node.z * factor.z), shifts), 0);
  high = uvec4(0u);
  if (factor.z == 2)
  {
    high = texelFetch(lower, atlasTexel(ivec3(node.xy, 2 * node.z + 1), shifts), 0);
  }
}

// One step down: from node (of the level above `lower`) to the child whose
// running sum, in visiting order, covers index. Levels are stored packed
// (texel (i, j, k) holds nodes (2i + a, 2j + b, k) in component a + 2b; see
// mediso::PyramidLayout), so the children of node n in z-slice z of the
// level below are the 4 components of texel (n.x, n.y, z), in child order
// dx + 2 dy (a component beyond an axis of one node holds 0): two fetches
// give all 8 counts. Straight-line code, no loop (factor is a literal at
// every call, so the second fetch folds away where z has one node): chained
// loops made llvmpipe's LLVM compile time double with every level.
void descend(usampler2D lower, ivec3 factor, ivec3 shifts, vec3 childSpan, inout ivec3 node,
  inout uint index)
{
  uvec4 low, high;
  childTexels(lower, factor, shifts, node, low, high);
  int child = pickChild(low, high, orderMask(node, factor, childSpan), index);
  node = node * factor + ivec3(child & 1, (child >> 1) & 1, (child >> 2) & 1);
}

#ifdef MEDISO_CHILD_MASKS
// The last step down, to a node of level 1, where level 1 holds child masks
// rather than counts (one isovalue: mediso::HistoPyramidGL::
// GetLevelOneHoldsChildMasks()): bit c of a node's component is set when its
// child cell c crosses the isovalue, so the node's count is the number of
// bits set and `bits` returns the chosen node's mask. The cells of the node
// then need no recount.

void descendToMasks(usampler2D lower, ivec3 factor, ivec3 shifts, vec3 childSpan,
  inout ivec3 node, inout uint index, out int bits)
{
  uvec4 low, high;
  childTexels(lower, factor, shifts, node, low, high);
  int child = pickChild(bitCount8(low), bitCount8(high), orderMask(node, factor, childSpan), index);
  node = node * factor + ivec3(child & 1, (child >> 1) & 1, (child >> 2) & 1);
  uvec4 layer = child < 4 ? low : high;
  int a = child & 3;
  bits = int(a < 2 ? (a == 0 ? layer.x : layer.y) : (a == 2 ? layer.z : layer.w));
}
#endif

// The cell's corner values and their central-difference gradients, mostly
// from the level-1 node's 27 points that the last step of the walk has read
// already (the node's cells are its children 0..7, so the cell and most of
// its neighbours lie in it).
//
// q[b + 4 d][a] is the value at point cell + (a, b, d) - 1 (a, b, d in
// 0..3): the cell's 4x4x4 neighbourhood, of which the 8 corners (a, b, d in
// 1..2) and the 24 neighbours along one axis of a corner (one index 0 or 3)
// are used. It is the node's 3x3x3 block shifted by the child's bits, one
// axis at a time with selects (the child varies per vertex, and software
// rasterisers spill arrays indexed by a variable). Along each axis one end
// of the 4 falls outside the node: index 0 for a lower child, 3 for an
// upper one; those 12 of the 24 neighbours are fetched (4 per axis), the
// other 12 and the 8 corners cost no fetch (20 fetches fewer per vertex).
// Points beyond the volume clamp to its border as in the node's block, so
// the difference is one-sided there (beyond the slot's brick in a pool: its
// border is the volume's wherever a read reaches it).
float outside(ivec3 p)
{
  return float(pointValue(clamp(p, slotOrigin, slotOrigin + slotCells)));
}

// The 4 values of a line of the neighbourhood from the node's 3 on it, for
// a lower (upper = false) or upper child; the end outside the node is a
// placeholder, replaced by a fetch.
vec4 shiftLine(bool upper, float n0, float n1, float n2)
{
  return vec4(n0, upper ? n1 : n0, upper ? n2 : n1, n2);
}

// The gradient at corner I = (DX, DY, DZ) of the cell. Along each axis the
// corner's neighbour inside the cell is another corner (v); the other is
// q's end of that line (index 0 beyond a corner on the cell's low side, 3
// beyond one on its high side).
#define MEDISO_GRADIENT(I, DX, DY, DZ)                                                      \
  {                                                                                        \
    ivec3 corner = c + ivec3(DX, DY, DZ);                                                  \
    vec3 inside = vec3(v[I ^ 1], v[I ^ 2], v[I ^ 4]);                                      \
    vec3 outer = vec3(q[1 + DY + 4 * (1 + DZ)][3 * DX], q[3 * DY + 4 * (1 + DZ)][1 + DX],   \
      q[1 + DY + 4 * 3 * DZ][1 + DX]);                                                     \
    vec3 sgn = vec3(DX == 0 ? 1.0 : -1.0, DY == 0 ? 1.0 : -1.0, DZ == 0 ? 1.0 : -1.0);       \
    ivec3 top = slotOrigin + slotCells;                                                    \
    vec3 span = vec3(1.0) + vec3(DX == 0 ? corner.x > slotOrigin.x : corner.x < top.x,     \
                               DY == 0 ? corner.y > slotOrigin.y : corner.y < top.y,       \
                               DZ == 0 ? corner.z > slotOrigin.z : corner.z < top.z);      \
    cornerGradients[I] = sgn * (inside - outer) / span;                                       \
  }

// Fills vLow, vHigh and cornerGradients for cell c, child `child` of the level-1
// node whose points (clamped to the volume) are p[i + 3 j + 9 k].
void cellCorners(ivec3 c, int child, VALUE_TYPE p[27])
{
  bvec3 upper = bvec3((child & 1) != 0, (child & 2) != 0, (child & 4) != 0);
  vec4 r[9]; // shifted along x: r[j + 3 k]
  for (int l = 0; l < 9; ++l)
  {
    r[l] = shiftLine(upper.x, float(p[3 * l]), float(p[3 * l + 1]), float(p[3 * l + 2]));
  }
  vec4 s[12]; // and along y: s[b + 4 k]
  for (int k = 0; k < 3; ++k)
  {
    s[4 * k] = r[3 * k];
    s[4 * k + 1] = upper.y ? r[3 * k + 1] : r[3 * k];
    s[4 * k + 2] = upper.y ? r[3 * k + 2] : r[3 * k + 1];
    s[4 * k + 3] = r[3 * k + 2];
  }
  vec4 q[16]; // and along z: q[b + 4 d]
  for (int b = 0; b < 4; ++b)
  {
    q[b] = s[b];
    q[b + 4] = upper.z ? s[b + 4] : s[b];
    q[b + 8] = upper.z ? s[b + 8] : s[b + 4];
    q[b + 12] = s[b + 8];
  }
  // The line ends outside the node: beyond the cell's low face for a lower
  // child, its high face for an upper one.
  ivec3 end = 3 * ivec3(upper) - 1;
  for (int e = 0; e < 4; ++e)
  {
    int i = 1 + (e & 1);
    int j = 1 + (e >> 1);
    float x = outside(c + ivec3(end.x, i - 1, j - 1));
    float y = outside(c + ivec3(i - 1, end.y, j - 1));
    float z = outside(c + ivec3(i - 1, j - 1, end.z));
    q[i + 4 * j] = upper.x ? vec4(q[i + 4 * j].xyz, x) : vec4(x, q[i + 4 * j].yzw);
    q[4 * j][i] = upper.y ? q[4 * j][i] : y;
    q[3 + 4 * j][i] = upper.y ? y : q[3 + 4 * j][i];
    q[j][i] = upper.z ? q[j][i] : z;
    q[j + 12][i] = upper.z ? z : q[j + 12][i];
  }
  float v[8];
  for (int i = 0; i < 8; ++i)
  {
    v[i] = q[1 + ((i >> 1) & 1) + 4 * (1 + (i >> 2))][1 + (i & 1)];
  }
  vLow = vec4(v[0], v[1], v[2], v[3]);
  vHigh = vec4(v[4], v[5], v[6], v[7]);
  MEDISO_GRADIENT(0, 0, 0, 0)
  MEDISO_GRADIENT(1, 1, 0, 0)
  MEDISO_GRADIENT(2, 0, 1, 0)
  MEDISO_GRADIENT(3, 1, 1, 0)
  MEDISO_GRADIENT(4, 0, 0, 1)
  MEDISO_GRADIENT(5, 1, 0, 1)
  MEDISO_GRADIENT(6, 0, 1, 1)
  MEDISO_GRADIENT(7, 1, 1, 1)
}

// Where, along one axis, the surface f = iso can meet the cell: a (b) holds
// the values of the 4 cell edges along that axis at its low (high) end. On a
// plane across the axis the interpolant is bilinear, with corners that vary
// linearly along those edges, so it takes the value iso on the plane only if
// those corners straddle iso. The planes where they do form a set whose
// bounds are edge crossings or an end whose face straddles iso, so that hull
// is returned (with a margin for rounding; the whole [0, 1] if anything is
// not finite).
vec2 axisRange(vec4 a, vec4 b, float iso)
{
  vec4 fa = a - iso;
  vec4 fb = b - iso;
  vec4 denominator = fa - fb;
  bvec4 crosses = lessThanEqual(fa * fb, vec4(0.0));
  bvec4 level = equal(denominator, vec4(0.0)); // crossing and flat: on the surface
  vec4 s = fa / mix(denominator, vec4(1.0), level);
  vec4 sLo = mix(vec4(2.0), mix(s, vec4(0.0), level), crosses);
  vec4 sHi = mix(vec4(-1.0), mix(s, vec4(1.0), level), crosses);
  float lo = min(min(sLo.x, sLo.y), min(sLo.z, sLo.w));
  float hi = max(max(sHi.x, sHi.y), max(sHi.z, sHi.w));
  if (min(min(fa.x, fa.y), min(fa.z, fa.w)) <= 0.0 && max(max(fa.x, fa.y), max(fa.z, fa.w)) >= 0.0)
  {
    lo = 0.0;
    hi = max(hi, 0.0);
  }
  if (min(min(fb.x, fb.y), min(fb.z, fb.w)) <= 0.0 && max(max(fb.x, fb.y), max(fb.z, fb.w)) >= 0.0)
  {
    lo = min(lo, 1.0);
    hi = 1.0;
  }
  if (!(lo >= 0.0 && hi <= 1.0 && lo <= hi))
  {
    return vec2(0.0, 1.0);
  }
  return clamp(vec2(lo - 1e-3, hi + 1e-3), 0.0, 1.0);
}

// The box, in the cell's [0, 1]^3, that holds the surface f = iso in it.
void surfaceBox(vec4 low, vec4 high, float iso, inout vec3 boxLo, inout vec3 boxHi)
{
  vec2 x = axisRange(vec4(low.x, low.z, high.x, high.z), vec4(low.y, low.w, high.y, high.w), iso);
  vec2 y = axisRange(vec4(low.x, low.y, high.x, high.y), vec4(low.z, low.w, high.z, high.w), iso);
  vec2 z = axisRange(low, high, iso);
  boxLo = min(boxLo, vec3(x.x, y.x, z.x));
  boxHi = max(boxHi, vec3(x.y, y.y, z.y));
}

// The footprint of the box [c + boxLo, c + boxHi] (see the header): the
// rectangle, in NDC, of its part in front of the near plane (its corners
// there and, for a quad, where its edges cross the plane), cut to the
// viewport, at the NDC depth of that part's nearest point. Off the clip
// volume when none of it is on screen.
void footprint(ivec3 c, vec3 boxLo, vec3 boxHi)
{
  vec3 size = boxHi - boxLo;
  vec4 origin = indexToClip * vec4(vec3(c) + boxLo, 1.0);
  vec4 dx = size.x * indexToClip[0];
  vec4 dy = size.y * indexToClip[1];
  vec4 dz = size.z * indexToClip[2];
  vec2 lo = vec2(1e30);
  vec2 hi = vec2(-1e30);
  float nearest = 1e30;
  vec4 corner[8];
  for (int i = 0; i < 8; ++i)
  {
    corner[i] = origin + float(i & 1) * dx + float((i >> 1) & 1) * dy + float((i >> 2) & 1) * dz;
    if (corner[i].z + corner[i].w >= 0.0 && corner[i].w > 0.0) // in front of the near plane
    {
      vec3 ndc = corner[i].xyz / corner[i].w;
      lo = min(lo, ndc.xy);
      hi = max(hi, ndc.xy);
      nearest = min(nearest, ndc.z);
    }
  }
#ifndef MEDISO_POINT_FOOTPRINT
  // The 12 edges (corner i to i + b, bit b not in i) that cross the near plane.
  for (int i = 0; i < 8; ++i)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      int b = 1 << axis;
      if ((i & b) == 0)
      {
        vec4 p = corner[i];
        vec4 q = corner[i + b];
        float dp = p.z + p.w;
        float dq = q.z + q.w;
        if ((dp >= 0.0) != (dq >= 0.0))
        {
          vec4 x = mix(p, q, dp / (dp - dq));
          lo = min(lo, x.xy / x.w);
          hi = max(hi, x.xy / x.w);
          nearest = -1.0;
        }
      }
    }
  }
#endif
  lo = max(lo, vec2(-1.0));
  hi = min(hi, vec2(1.0));
  if (any(greaterThan(lo, hi)) || nearest > 1.0)
  {
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0); // clipped
#ifdef MEDISO_POINT_FOOTPRINT
    gl_PointSize = 1.0;
#endif
    vNearDepth = 1.0;
    return;
  }
  vNearDepth = max(nearest, -1.0);
#ifdef MEDISO_FIRST_HIT
  // First-hit pass (opaque, the renderer's own depth buffer): every
  // primitive at one depth, with the depth test GL_LESS, so a fragment
  // passes only where no earlier primitive has hit; the primitives come
  // front to back, so the first hit is the nearest. The depth test runs
  // before the fragment stage, which then writes no gl_FragDepth.
  float depth = 0.0;
#else
  float depth = vNearDepth;
#endif
  // A footprint covers the pixels whose centres lie in it; a margin of a
  // tenth of a pixel (plus the point size granularity) keeps those whose
  // centres lie on its edges, whatever the rasteriser's tie rule. (A whole
  // pixel of margin would cost a small point far more fragments.)
#ifdef MEDISO_POINT_FOOTPRINT
  vec2 pixels = 0.5 * (hi - lo) * viewportSize;
  gl_PointSize = min(max(pixels.x, pixels.y) + pointMargin, maxPointSize);
  gl_Position = vec4(0.5 * (lo + hi), depth, 1.0);
#ifdef MEDISO_HIT_CULL
  if (cullHidden == 1 && pointCovered(gl_Position.xy, gl_PointSize))
  {
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0); // beyond the far plane: clipped before its setup
    gl_PointSize = 1.0;
  }
#endif
#else
  vec2 margin = pointMargin / viewportSize; // half the margin on each side, in NDC
  vec2 corner01 = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
  gl_Position = vec4(mix(lo - margin, hi + margin, corner01), depth, 1.0);
#endif
}

#ifdef MEDISO_CULL_CELLS
// Whether the whole cell [c, c + 1] lies outside the view: all its corners
// beyond one of the clip volume's planes (the near plane included). The
// surface box lies in the cell, so its footprint would be off screen too;
// testing here skips the corner gradients' fetches for such cells, most of
// the cells in a close zoom. (Compiled in only when part of the volume is off
// screen.)
bool cellOffScreen(ivec3 c)
{
  vec4 origin = indexToClip * vec4(vec3(c), 1.0);
  bvec4 allPlus = bvec4(true);  // x > w, y > w, z > w, (unused)
  bvec4 allMinus = bvec4(true); // x < -w, y < -w, z < -w, (unused)
  for (int i = 0; i < 8; ++i)
  {
    vec4 p = origin + float(i & 1) * indexToClip[0] + float((i >> 1) & 1) * indexToClip[1] +
      float((i >> 2) & 1) * indexToClip[2];
    allPlus = bvec4(allPlus.x && p.x > p.w, allPlus.y && p.y > p.w, allPlus.z && p.z > p.w, false);
    allMinus =
      bvec4(allMinus.x && p.x < -p.w, allMinus.y && p.y < -p.w, allMinus.z && p.z < -p.w, false);
  }
  return any(allPlus) || any(allMinus);
}
#endif

#ifdef MEDISO_CLIP_PLANES
uniform vec4 clipPlanes[MEDISO_CLIP_PLANES]; // index space; a p + w >= 0 is kept

// Whether the whole cell [c, c + 1] lies on the removed side of a clipping
// plane: the plane's largest value over the cell's corners is negative. The
// fragment stage would find no hit in such a cell; skipping it here saves
// its corner fetches and footprint.
bool cellClippedAway(ivec3 c)
{
  for (int i = 0; i < MEDISO_CLIP_PLANES; ++i)
  {
    vec4 plane = clipPlanes[i];
    if (dot(plane.xyz, vec3(c)) + plane.w + dot(max(plane.xyz, vec3(0.0)), vec3(1.0)) < 0.0)
    {
      return true;
    }
  }
  return false;
}
#endif

void main()
{
  uint index = uint(MEDISO_PRIMITIVE);
  ivec3 node;
  startWalk(index, node);
#ifdef MEDISO_CHILD_MASKS
  int nodeBits = 0; // the level-1 node's child mask, from its last step down
#endif

//MEDISO::HistoPyramidDescent

  // Last step: the cells of the level-1 node, counted from the volume: the
  // node's <= 27 points are read once and each child cell's crossing mask is
  // made from them with constant indices.
  // A row of the node's 3 points along x starts at an even x, so it lies in
  // one stored texel (x = 4i: components 0..2) or two (x = 4i + 2: 2, 3 and
  // the next texel's 0): 18 fetches instead of 27.
  ivec3 first = node * firstFactor;
  VALUE_TYPE p[27];
  int texelX = first.x >> 2;
  bool secondHalf = (first.x & 2) != 0;
  for (int r = 0; r < 9; ++r) // row r: points first + (0..2, r % 3, r / 3)
  {
    int y = min(first.y + r % 3, slotOrigin.y + slotCells.y);
    int z = min(first.z + r / 3, slotOrigin.z + slotCells.z);
    VALUE_VEC4 a = pointQuad(texelX, y, z);
    VALUE_VEC4 b = pointQuad(texelX + 1, y, z);
    p[3 * r] = secondHalf ? a.z : a.x;
    p[3 * r + 1] = secondHalf ? a.w : a.y;
    p[3 * r + 2] = secondHalf ? b.x : a.z;
  }
  ivec4 masksLow, masksHigh; // child c's crossing mask: c < 4 ? masksLow[c] : masksHigh[c - 4]
#ifdef MEDISO_CHILD_MASKS
  // One isovalue: the masks came with the last step down (a cell's crossing
  // mask is then its bit, and its count the same bit).
  masksLow = (ivec4(nodeBits) >> ivec4(0, 1, 2, 3)) & 1;
  masksHigh = (ivec4(nodeBits) >> ivec4(4, 5, 6, 7)) & 1;
  uvec4 countsLow = uvec4(masksLow);
  uvec4 countsHigh = uvec4(masksHigh);
#else
#define MEDISO_CHILD(C, X, Y, Z)                                                             \
  {                                                                                         \
    VALUE_TYPE w[8];                                                                        \
    MEDISO_CHILD_CORNERS(w, p, X, Y, Z)                                                     \
    int m = any(greaterThanEqual(ivec3(X, Y, Z), firstFactor)) ? 0                          \
                                                               : cellMask(first + ivec3(X, Y, Z), w); \
    if (C < 4)                                                                              \
      masksLow[C & 3] = m;                                                                  \
    else                                                                                    \
      masksHigh[C & 3] = m;                                                                 \
  }
  MEDISO_CHILD(0, 0, 0, 0)
  MEDISO_CHILD(1, 1, 0, 0)
  MEDISO_CHILD(2, 0, 1, 0)
  MEDISO_CHILD(3, 1, 1, 0)
  MEDISO_CHILD(4, 0, 0, 1)
  MEDISO_CHILD(5, 1, 0, 1)
  MEDISO_CHILD(6, 0, 1, 1)
  MEDISO_CHILD(7, 1, 1, 1)
  uvec4 countsLow = bitCount8(uvec4(masksLow));
  uvec4 countsHigh = bitCount8(uvec4(masksHigh));
#endif
  int c = pickChild(countsLow, countsHigh, orderMask(node, firstFactor, vec3(1.0)), index);
  ivec3 cell = first + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  int mask = c < 4 ? masksLow[c & 3] : masksHigh[c & 3];
  // Where the cell lies in the volume (a pool's slot holds its brick elsewhere).
  ivec3 placed = cell - slotOrigin + slotPlacement;
  vCellMask = ivec4(placed, mask);
  // The index-th crossing isovalue, in increasing threshold order.
  vIsovalue = -1;
  int rank = int(index);
  for (int t = 0; t < 8; ++t)
  {
    int bit = (mask >> t) & 1;
    vIsovalue = bit == 1 && rank == 0 && vIsovalue < 0 ? t : vIsovalue;
    rank -= bit;
  }
  if (oneRankPerCell == 1 && index != 0u)
  {
    vIsovalue = -1;
  }
#ifdef MEDISO_CULL_CELLS
  if (vIsovalue >= 0 && cellOffScreen(placed))
  {
    vIsovalue = -1;
  }
#endif
#ifdef MEDISO_CLIP_PLANES
  if (vIsovalue >= 0 && cellClippedAway(placed))
  {
    vIsovalue = -1;
  }
#endif
  if (vIsovalue >= 0)
  {
    vLook = vec4(isoColors[vIsovalue].rgb, isovalues[vIsovalue]);
    cellCorners(cell, c, p);
    vGradients[0] = vec4(cornerGradients[0], cornerGradients[1].x);
    vGradients[1] = vec4(cornerGradients[1].yz, cornerGradients[2].xy);
    vGradients[2] = vec4(cornerGradients[2].z, cornerGradients[3]);
    vGradients[3] = vec4(cornerGradients[4], cornerGradients[5].x);
    vGradients[4] = vec4(cornerGradients[5].yz, cornerGradients[6].xy);
    vGradients[5] = vec4(cornerGradients[6].z, cornerGradients[7]);
  }
  if (vIsovalue >= 0)
  {
    vec3 boxLo = vec3(1.0);
    vec3 boxHi = vec3(0.0);
#if defined(MEDISO_TRANSLUCENT) || defined(MEDISO_NEAREST)
    for (int t = 0; t < MEDISO_ISOVALUES; ++t) // the cell's one primitive draws them all
    {
      if (((mask >> t) & 1) == 1)
      {
        surfaceBox(vLow, vHigh, isovalues[t], boxLo, boxHi);
      }
    }
#else
    surfaceBox(vLow, vHigh, vLook.w, boxLo, boxHi);
#endif
    footprint(placed, boxLo, boxHi);
  }
  else
  {
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
#ifdef MEDISO_POINT_FOOTPRINT
    gl_PointSize = 1.0;
#endif
    vNearDepth = 1.0;
  }
}
