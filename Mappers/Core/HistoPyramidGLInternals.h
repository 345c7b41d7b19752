// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file HistoPyramidGLInternals.h
 * @brief The GL objects of HistoPyramidGL (private to the GPU core; the
 * drawing program of IsosurfaceRendererGL reads the same textures).
 */
#ifndef MedicalIsosurfaces_HistoPyramidGLInternals_h
#define MedicalIsosurfaces_HistoPyramidGLInternals_h

#include "GLObjects.h"
#include "HistoPyramidGL.h"
#include "IsoThresholds.h"

#include <array>

namespace mediso
{

struct HistoPyramidGL::Internals
{
  std::shared_ptr<const GLApi> GL;
  GLParallelFor Parallel;

  // The volume: a 3D texture, 4 points to a texel along x.
  glcore::Name Volume;
  ScalarType Type = ScalarType::Float32;
  int Points[3] = { 0, 0, 0 };
  PyramidLayout Layout;

  // Per level-1 tile, the least and greatest value its cells read (CPU),
  // in the type the thresholds have (by the volume's value kind).
  std::vector<std::int32_t> IntRanges;
  std::vector<std::uint32_t> UIntRanges;
  std::vector<float> FloatRanges;

  // The stored levels (index = level; 0 is empty), each a 2D atlas.
  std::vector<glcore::Name> Levels;
  bool Built = false;
  std::uint64_t Total = 0;
  IsoThresholds Current; // of the last successful Build()
  bool ChildMasks = false;
  std::uint64_t TilesDrawn = 0;

  // The passes.
  glcore::Name FBO;
  glcore::Name TileBuffer;      // the level-1 pass's rectangles
  glcore::Name TileVertexArray; // with attribute 0 reading TileBuffer
  glcore::Name EmptyVertexArray;
  glcore::ProgramCache Programs;

  /// A stored level's atlas layout as the shaders take it: log2 of px, py, columns.
  std::array<int, 3> Shifts(int level) const;
  /// The value type's #defines.
  std::string Declarations() const;
  /// The hook that puts HistoPyramidCommon.glsl in a shader.
  glcore::Hooks CommonHooks() const;
  /// The uniforms of HistoPyramidCommon.glsl on the bound program; the volume is on `volumeUnit`.
  void SetCommonUniforms(glcore::Program& program, const IsoThresholds& t, int volumeUnit) const;

  std::vector<std::uint16_t> ActiveTileRectangles(
    const IsoThresholds& thresholds, std::uint64_t& tilesDrawn) const;
  bool Target(GLuint texture, int width, int height, std::string& error);
  glcore::Program* Pass(
    const char* vertex, const char* fragment, const std::string& defines, std::string& error);
  void DrawFullScreen();
  void ReleaseLevels();
  void ReleaseAll();
};

} // namespace mediso

#endif
