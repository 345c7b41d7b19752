// SPDX-License-Identifier: BSD-3-Clause
//
// HistoPyramidReduce_fs.glsl: one level of the GPU HistoPyramid
// (mediso::HistoPyramidGL) from the level below. Every stored level is
// packed: texel (i, j, k) holds the counts of the 2x2 nodes (2i + a, 2j + b,
// k), component a + 2b (a node beyond the level's size counts 0), in a 2D
// atlas (see HistoPyramidCommon.glsl). Drawn over the whole atlas of level
// l + 1: each fragment writes the counts of its 4 nodes n, each the sum of
// n's children in level l, the box [2n.x, 2n.x + fx) x [2n.y, 2n.y + fy) x
// [2n.z, 2n.z + fz) (f is 2 along an axis that level l still has more than
// one node on, else 1: the layout of mediso::PyramidLayout). Packed, the
// children of n in slice z of level l are all 4 components of texel
// (n.x, n.y, z) of level l (along an axis with f = 1, level l has one node,
// n is 0 there and the other component is a node beyond the level: 0), so
// a node reads fz texels.

//MEDISO::HistoPyramidCommon

uniform usampler2D lowerLevel; // atlas of level l, texelFetch only
uniform ivec3 lowerShifts;     // its layout (see atlasTexel())
uniform ivec3 shifts;          // the layout of level l + 1
uniform ivec3 factor;          // 1 or 2 per axis
uniform ivec3 levelSize;       // nodes of level l + 1

MEDISO_OUTPUT(0) uvec4 fragOutput0;

// The sum of 4 counts or, where the level below is level 1 holding child
// masks (MEDISO_LOWER_CHILD_MASKS: one isovalue, see mediso::HistoPyramidGL::
// GetLevelOneHoldsChildMasks()), of the set bits of 4 masks of 8 bits.
uint sum4(uvec4 v)
{
#ifdef MEDISO_LOWER_CHILD_MASKS
  v = bitCount8(v);
#endif
  return v.x + v.y + v.z + v.w;
}

uint nodeCount(ivec3 node)
{
  if (any(greaterThanEqual(node, levelSize)))
  {
    return 0u;
  }
  uint count = sum4(texelFetch(lowerLevel, atlasTexel(ivec3(node.xy, node.z * factor.z), lowerShifts), 0));
  if (factor.z == 2)
  {
    count += sum4(texelFetch(lowerLevel, atlasTexel(ivec3(node.xy, 2 * node.z + 1), lowerShifts), 0));
  }
  return count;
}

void main()
{
  ivec3 texel = packedTexel(ivec2(gl_FragCoord.xy), shifts);
  ivec3 first = ivec3(2 * texel.xy, texel.z);
  fragOutput0 = uvec4(nodeCount(first), nodeCount(first + ivec3(1, 0, 0)),
    nodeCount(first + ivec3(0, 1, 0)), nodeCount(first + ivec3(1, 1, 0)));
}
