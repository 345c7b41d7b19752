// SPDX-License-Identifier: BSD-3-Clause
#include "GLProbe.h"

#include "GLObjects.h"
#include "MedisoShaders.h"

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <vector>

namespace mediso
{
namespace
{
using namespace glcore;

constexpr int ProbeNX = 9;
constexpr int ProbeNY = 7;
constexpr int ProbeNZ = 5;
constexpr int ProbeCellsX = ProbeNX - 1;
constexpr int ProbeCellsY = ProbeNY - 1;
constexpr int ProbeTexelsX = (ProbeNX + 3) / 4; // stored 4 points to a texel along x

// An off-centre ellipsoidal distance field (negative inside, -8699 .. 18150)
// plus a small aperiodic ripple.
std::int16_t ProbeValue(int i, int j, int k)
{
  const int di = 3 * i - 10;
  const int dj = 3 * j - 8;
  const int dk = 3 * k - 5;
  const int d2 = di * di + 2 * dj * dj + 3 * dk * dk;
  return static_cast<std::int16_t>((d2 - 180) * 50 + (i * 3 + j * 5 + k * 7) % 5 - 2);
}

// The probe volume as the core stores a volume: 4 points to a texel along x,
// the last texel of a row repeating the row's last point.
std::vector<std::int16_t> ProbeVolume()
{
  const int rowLength = 4 * ProbeTexelsX;
  std::vector<std::int16_t> values(static_cast<std::size_t>(rowLength) * ProbeNY * ProbeNZ);
  for (int k = 0; k < ProbeNZ; ++k)
    for (int j = 0; j < ProbeNY; ++j)
      for (int i = 0; i < rowLength; ++i)
      {
        values[(static_cast<std::size_t>(k) * ProbeNY + j) * rowLength + i] =
          ProbeValue(std::min(i, ProbeNX - 1), j, k);
      }
  return values;
}

// The CPU's count of active cells per (i, j) column, i fastest.
std::vector<unsigned int> ColumnCounts(float iso)
{
  std::vector<unsigned int> counts(static_cast<std::size_t>(ProbeCellsX) * ProbeCellsY, 0u);
  for (int j = 0; j < ProbeCellsY; ++j)
    for (int i = 0; i < ProbeCellsX; ++i)
    {
      unsigned int count = 0;
      for (int k = 0; k < ProbeNZ - 1; ++k)
      {
        float lo = 1.0e30f, hi = -1.0e30f;
        for (int c = 0; c < 8; ++c)
        {
          const float v = ProbeValue(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
        count += lo < iso && iso <= hi ? 1u : 0u;
      }
      counts[static_cast<std::size_t>(j) * ProbeCellsX + i] = count;
    }
  return counts;
}
} // namespace

ProbeResult ProbeGL(const GLApi& gl, std::string& reason)
{
  const GLApi::Functions& f = gl.F();
  ScopedGLState saved(gl, 1);
  gl.TakeErrors();
  SetCountingPassState(gl);

  Name volume(gl, NameKind::Texture), counts(gl, NameKind::Texture);
  Name fbo(gl, NameKind::Framebuffer), vertexArray(gl, NameKind::VertexArray);
  const std::vector<std::int16_t> values = ProbeVolume();
  BindTextureUnit(gl, 0, GL_TEXTURE_3D, volume.Get());
  SetNearest(gl, GL_TEXTURE_3D);
  f.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  f.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  f.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
  f.TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA16I, ProbeTexelsX, ProbeNY, ProbeNZ, 0, GL_RGBA_INTEGER,
    GL_SHORT, values.data());
  std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    reason = "an RGBA16I 3D texture cannot be made (" + errors + ")";
    return ProbeResult::MissingFeature;
  }
  BindTextureUnit(gl, 0, GL_TEXTURE_2D, counts.Get());
  SetNearest(gl, GL_TEXTURE_2D);
  f.TexImage2D(GL_TEXTURE_2D, 0, GL_R32UI, ProbeCellsX, ProbeCellsY, 0, GL_RED_INTEGER,
    GL_UNSIGNED_INT, nullptr);
  f.BindFramebuffer(GL_FRAMEBUFFER, fbo.Get());
  f.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, counts.Get(), 0);
  const GLenum buffer = GL_COLOR_ATTACHMENT0;
  f.DrawBuffers(1, &buffer);
  f.ReadBuffer(GL_COLOR_ATTACHMENT0);
  const std::string problem = FramebufferProblem(gl);
  errors = gl.TakeErrors();
  if (!problem.empty() || !errors.empty())
  {
    reason = "an R32UI render target cannot be made (" + (problem.empty() ? errors : problem) + ")";
    return ProbeResult::MissingFeature;
  }
  std::string error;
  std::unique_ptr<Program> program =
    BuildProgram(gl, "", shaders::HistoPyramidFullScreen_vs, shaders::MedicalProbe_fs, error);
  if (!program)
  {
    reason = "the probe shader does not build: " + error;
    return ProbeResult::Failed;
  }
  program->Use();
  BindTextureUnit(gl, 0, GL_TEXTURE_3D, volume.Get());
  program->Set("probeVolume", 0);
  const int points[3] = { ProbeNX, ProbeNY, ProbeNZ };
  program->Set3i("probePoints", points);
  f.BindVertexArray(vertexArray.Get());
  f.Viewport(0, 0, ProbeCellsX, ProbeCellsY);
  f.PixelStorei(GL_PACK_ALIGNMENT, 4);
  for (const float iso : { -2000.0f, 0.5f, 4321.0f })
  {
    program->Set("isovalue", iso);
    f.DrawArrays(GL_TRIANGLES, 0, 3);
    std::vector<GLuint> texels(4 * static_cast<std::size_t>(ProbeCellsX) * ProbeCellsY, 0xdeadu);
    f.ReadPixels(0, 0, ProbeCellsX, ProbeCellsY, GL_RGBA_INTEGER, GL_UNSIGNED_INT, texels.data());
    errors = gl.TakeErrors();
    if (!errors.empty())
    {
      reason = "the probe pass failed: " + errors;
      return ProbeResult::Failed;
    }
    const std::vector<unsigned int> expected = ColumnCounts(iso);
    for (int j = 0; j < ProbeCellsY; ++j)
      for (int i = 0; i < ProbeCellsX; ++i)
      {
        const std::size_t at = static_cast<std::size_t>(j) * ProbeCellsX + i;
        if (texels[4 * at] != expected[at])
        {
          std::ostringstream os;
          os << "probe count mismatch at (" << i << ", " << j << ") for isovalue " << iso << ": GPU "
             << texels[4 * at] << ", CPU " << expected[at];
          reason = os.str();
          return ProbeResult::Failed;
        }
      }
  }
  return ProbeResult::Passed;
}

} // namespace mediso
