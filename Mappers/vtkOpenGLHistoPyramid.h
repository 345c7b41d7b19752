// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkOpenGLHistoPyramid
 * @brief   Builds the 3D HistoPyramid of a scalar volume on the GPU (OpenGL 3.2).
 *
 * vtkOpenGLHistoPyramid is the GPU half of the cell-rasterisation isosurface
 * mapper: it counts, for every cell of a volume, how many of up to eight
 * isovalues cross it, and sums those counts up a 3D 8:1 HistoPyramid
 * (Ziegler, Tevs, Theobalt & Seidel, "On-the-fly point clouds through
 * histogram pyramids", VMV 2006). The mapper then draws GetTotal() primitives
 * and each one finds its cell by walking down the pyramid (Liu, Clapworthy &
 * Dong, "Octree based HistoPyramid", 2009; the cell-rasterisation scheme of
 * "Hardware Accelerated Medical Data Visualisation on the Web", section 4.1).
 *
 * The layout is exactly the one of the CPU reference mediso::HistoPyramid
 * (Mappers/Core/HistoPyramid.h), so that both can be compared number for
 * number: level 0 is the cell grid padded to a power of two per axis (padding
 * cells count 0), and each level above halves every axis larger than 1, down
 * to a single 1x1x1 node (a one-cell volume still gets a level 1).
 *
 * Memory. Level 0 is never stored: level 1 is computed straight from the
 * volume (each node reads the <= 27 corner values of its <= 8 cells once),
 * and the traversal recounts the cells of the level-1 node it reaches from
 * the same corner values, which it needs anyway to draw the cell. With one
 * isovalue, level 1 holds each node's child mask instead of its count (see
 * GetLevelOneHoldsChildMasks()), in the same bytes, and the traversal reads
 * which cells are active with no recount. Each stored
 * level takes the narrowest unsigned integer format that holds its largest
 * possible count (8 isovalues times the cells under a node): 8 bits for
 * level 1, 16 up to level 4, 32 above. The whole pyramid is then about 0.16
 * bytes per padded cell, against 4.6 for R32UI levels from an R32UI base, so
 * the GPU memory stays close to the volume's own size (a 256x256x108 int16
 * CT: 14.2 MB volume + 1.4 MB pyramid).
 *
 * Packing. Each stored level is an RGBA texture (GL_RGBA8UI, GL_RGBA16UI or
 * GL_RGBA32UI) of half the level's size in x and y: texel (i, j, k) holds
 * the counts of the 2x2 nodes (2i + a, 2j + b, k) in component a + 2b (a
 * node beyond the level, where an axis has one node, counts 0). The same
 * bytes as one node per texel, but the 8 children of a node of the level
 * above are then the 4 components of 2 texels, (n.x, n.y, 2 n.z) and
 * (n.x, n.y, 2 n.z + 1): a step of the mapper's walk down the pyramid is 2
 * texel fetches instead of 8, and the walk is most of the vertex stage's
 * work on a software rasteriser. ReadLevel() unpacks.
 *
 * Only OpenGL 3.2 core / GLSL 1.50 is used (no compute shaders, no shader
 * storage buffers, no image load/store). The build is one draw call per
 * level: the level's 3D texture is attached whole as a layered framebuffer
 * attachment, and an instanced full-screen quad per z-slice
 * (vtkHistoPyramidLayer_vs.glsl) is routed to its slice by a geometry shader
 * setting gl_Layer (vtkHistoPyramidLayer_gs.glsl); the fragment stages write
 * an unsigned integer output (a handful of draw calls per rebuild instead of
 * one per slice and level).
 * -# Level-1 pass (vtkHistoPyramidFirstLevel_fs.glsl): fragment (i, j) of
 *    slice k is the packed texel of nodes (2i + a, 2j + b, k); each node
 *    sums over its cells the number of isovalues with min < iso <= max
 *    over the cell's eight corners (the convention of vtkMarchingCubes);
 *    with one isovalue it writes the node's child mask instead, whose set
 *    bits the reduction to level 2 counts (a compiled variant of each pass).
 *    Only the tiles of the level (TileNodes x TileNodes x 1 nodes) that can
 *    hold an active cell are drawn: UploadVolume() computes, once, the range
 *    of the point values each tile's cells read (a small RG32 texture, 8
 *    bytes per tile); the level is cleared to 0, and one point per tile
 *    (vtkHistoPyramidFirstLevel_vs.glsl) becomes a quad on its slice
 *    (vtkHistoPyramidFirstLevel_gs.glsl) only where an isovalue lies in that
 *    range. A tile's points are connected by cell edges, so that happens
 *    exactly when one of its cells crosses the isovalue: the pass costs what
 *    the surface touches (on the 256x256x108 CT a skin or bone isovalue
 *    crosses 30% of the tiles), not the whole volume. This is the build's
 *    main cost: the reductions above it read 1/8 of the level below each.
 *    Cells with a NaN corner and padding cells count 0. The test is the one
 *    function of vtkHistoPyramidCommon.glsl that every pass and the drawing
 *    program share. The comparisons are exact: isovalues are turned on the CPU into
 *    thresholds of the texture's own value type (ceil(iso) for integer data,
 *    the smallest float >= iso for float data), so that the GPU counts equal
 *    the CPU counts computed in double precision.
 * -# Reduction passes (vtkHistoPyramidReduce_fs.glsl): each fragment writes
 *    a packed texel of level l + 1; each of its nodes is the sum of its
 *    2x2x2 children of level l (2x2x1, 2x1x1, ... once an axis has reached
 *    1), the components of 1 or 2 texels read with texelFetch.
 * -# Read-back: only the top node (component 0 of one texel) comes back to
 *    the CPU, as GetTotal().
 *
 * The volume is uploaded once by UploadVolume() and kept until it is called
 * again, as a 3D texture that keeps the data's precision and holds 4 points
 * to a texel along x: texel (i, j, k) holds points (4i + c, j, k) in
 * component c, and where a row's points run out its last texel repeats the
 * row's last point. Signed/unsigned char go to GL_RGBA8I/GL_RGBA8UI,
 * short/unsigned short to GL_RGBA16I/GL_RGBA16UI, int/unsigned int to
 * GL_RGBA32I/GL_RGBA32UI (all read with texelFetch from an isampler3D or
 * usampler3D), float to GL_RGBA32F (sampler3D). These are the data's own
 * bytes (with a multiple of 4 points per row, the array is uploaded as it
 * is), but the passes that read rows of points need a fetch per 4 of them:
 * a texel of level 1 (the 5x5x3 points of its 4 nodes) takes 30 fetches
 * instead of 108, which halved the build on the test volumes, and the
 * traversal's level-1 node 18 instead of 27. Double data is converted to
 * float (GL_RGBA32F): counts then match a CPU reference computed on the
 * double values only where those values are representable as floats.
 *
 * Every call saves and restores the OpenGL state it changes (current context,
 * framebuffer bindings, draw/read buffers, viewport, blend/depth/scissor/
 * stencil/cull enables, colour mask, active texture unit, pixel store
 * alignment and pixel buffer bindings, bound program), so it can run inside a
 * render. The mapper that owns it must call ReleaseGraphicsResources() when
 * its window releases its resources.
 *
 * @warning Counts are 32-bit: the total must stay below 2^32 (a volume of
 * 512^3 cells with 8 isovalues crossing every cell would overflow).
 *
 * @sa vtkMedicalGLCapabilities mediso::HistoPyramid
 */
#ifndef vtkOpenGLHistoPyramid_h
#define vtkOpenGLHistoPyramid_h

#include "MedicalIsosurfacesMappersModule.h" // For export macro
#include "vtkObject.h"

#include <cstdint> // For std::uint32_t
#include <memory>  // For std::unique_ptr
#include <string>  // For std::string
#include <vector>  // For std::vector

class vtkDataArray;
class vtkOpenGLRenderWindow;
class vtkShaderProgram;
class vtkTextureObject;
class vtkWindow;

class MEDICALISOSURFACESMAPPERS_EXPORT vtkOpenGLHistoPyramid : public vtkObject
{
public:
  static vtkOpenGLHistoPyramid* New();
  vtkTypeMacro(vtkOpenGLHistoPyramid, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Most isovalues one Build() can count (a uniform array of the base pass).
  static constexpr int MaximumNumberOfIsovalues = 8;

  /**
   * Level-1 nodes per side of a tile of the level-1 pass: a tile is
   * TileNodes x TileNodes x 1 nodes of level 1 (16 x 16 x 2 cells where the
   * level-1 factor is 2), cut at the level's edges.
   */
  static constexpr int TileNodes = 8;

  /**
   * Upload the single-component @a scalars of a volume of @a pointDims points
   * (x fastest, each >= 2) as a 3D texture (see the class description for the
   * formats). Replaces the previous volume and invalidates the pyramid.
   * Returns false, with an error, on an unsupported array or a GL failure.
   */
  bool UploadVolume(vtkOpenGLRenderWindow* renWin, vtkDataArray* scalars, const int pointDims[3]);

  /**
   * Build the pyramid of the uploaded volume for 1 to
   * MaximumNumberOfIsovalues @a isovalues (NaN ones count nothing) and read
   * back the total. Reuses the level textures while the volume size stays.
   */
  bool Build(vtkOpenGLRenderWindow* renWin, const std::vector<double>& isovalues);

  /// Number of primitives of the last successful Build() (0 before).
  std::uint64_t GetTotal() const;

  /// Number of levels of the last successful Build(), base (0) to top; 0 before.
  int GetNumberOfLevels() const;

  /**
   * Read a whole level back (x fastest) and its size, for tests. Needs the
   * window of the last Build() to be alive. Level 0, which is not stored, is
   * drawn into a temporary texture by the same crossing code first
   * (vtkHistoPyramidBase_fs.glsl). Returns false when there is no such level
   * or reading fails. Level 1 comes back as counts even where it holds child
   * masks (GetLevelOneHoldsChildMasks()), unless @a asStored is true: then
   * each node's value as stored.
   */
  bool ReadLevel(int level, std::vector<std::uint32_t>& counts, int size[3], bool asStored = false);

  /// Size of a level of the last successful Build(); false when there is none.
  bool GetLevelSize(int level, int size[3]) const;

  ///@{
  /**
   * For a drawing program that traverses the pyramid (the isosurface
   * mapper): the texture of a stored level (1 .. GetNumberOfLevels() - 1;
   * nullptr otherwise or before Build()) and the volume texture.
   */
  vtkTextureObject* GetLevelTexture(int level) const;
  vtkTextureObject* GetVolumeTexture() const;
  ///@}

  /**
   * GLSL for a drawing program: the #defines of the volume's value type
   * (VALUE_SAMPLER, VALUE_TYPE, VALUE_IS_FLOAT) and vtkHistoPyramidCommon.glsl
   * (the crossing test the pyramid was built with, and its uniforms).
   */
  std::string GetShaderDeclarations() const;

  /**
   * Set the uniforms of GetShaderDeclarations() on the bound @a program for
   * the last Build(). The volume texture must be active (Activate()).
   */
  void SetShaderUniforms(vtkShaderProgram* program) const;

  /**
   * Which of the last Build()'s isovalues the pyramid counts, by index, in the
   * order of bit t of the shaders' crossing masks. Isovalues that can cross
   * no cell of the volume's value type (and NaN ones) are left out.
   */
  std::vector<int> GetCountedIsovalues() const;

  /**
   * Whether the last successful Build() stored level 1 as child masks rather
   * than counts: with one counted isovalue (and a level 2 above level 1),
   * component a + 2b of a level-1 texel holds bit c set when child cell c
   * (dx + 2 dy + 4 dz) of node (2i + a, 2j + b, k) crosses the isovalue, so
   * the node's count is its number of bits set. The same bytes as the counts
   * (a node's count is at most 8 then), and a walk that reaches a level-1
   * node reads which of its cells are active with no recount
   * (vtkHistoPyramidIso_vs.glsl, MEDISO_CHILD_MASKS). ReadLevel() returns
   * counts either way.
   */
  bool GetLevelOneHoldsChildMasks() const;

  ///@{
  /**
   * The level-1 pass's tiles: how many there are for the uploaded volume
   * (0 before), and how many the last successful Build() drew (those whose
   * value range holds an isovalue; 0 before). See the class description.
   */
  std::uint64_t GetNumberOfTiles() const;
  std::uint64_t GetLastTilesDrawn() const;
  ///@}

  /// Bytes of the GPU textures this object owns now (volume, tile ranges, levels).
  std::uint64_t GetGPUMemoryBytes() const;

  /**
   * Release every OpenGL object (volume, levels, framebuffer, programs).
   * UploadVolume() must be called again before the next Build().
   */
  void ReleaseGraphicsResources(vtkWindow* win);

protected:
  vtkOpenGLHistoPyramid();
  ~vtkOpenGLHistoPyramid() override;

private:
  vtkOpenGLHistoPyramid(const vtkOpenGLHistoPyramid&) = delete;
  void operator=(const vtkOpenGLHistoPyramid&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
