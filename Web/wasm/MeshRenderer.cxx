// SPDX-License-Identifier: BSD-3-Clause
#include "MeshRenderer.h"

#include "GLApiFunctions.h"
#include "GLObjects.h"
#include "Lighting.h"
#include "WebShaders.h"

#include <algorithm>
#include <cstring>

namespace mediso
{
namespace web
{
namespace
{
using namespace glcore;

// A run of a mesh's triangles drawn with 16-bit indices counted from its
// first point (the attributes are pointed there: WebGL2 has no base vertex).
struct Chunk
{
  std::int64_t FirstTriangle = 0, Triangles = 0;
  std::uint32_t FirstPoint = 0;
};

struct Mesh
{
  Name VertexArray, Vertices, Indices;
  std::int64_t Triangles = 0;
  std::vector<Chunk> Chunks; // empty: one draw with 32-bit indices
  // A point is Offset + Scale * its stored position (PackVertices).
  float Offset[3] = { 0.0f, 0.0f, 0.0f };
  float Scale[3] = { 1.0f, 1.0f, 1.0f };
  float Color[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
  bool Visible = true;
};
// Bytes of a packed point: its position as four normalized 16-bit integers
// (the fourth unused: four-component formats are the ones every Vulkan device
// reads as vertex input, which ANGLE would otherwise convert), its normal as
// four normalized signed bytes.
constexpr int PackedPointBytes = 12;

// Points and normals packed for the upload, interleaved: positions quantized
// within the mesh's bounds (`mesh`'s Offset and Scale give them back), normals
// at 8 bits a component. Half the bytes of three floats each: the upload and
// the software rasteriser's vertex fetch are half as long. The quantization
// step, 1/65535 of the mesh's extent, is far below a pixel.
std::vector<std::uint8_t> PackVertices(
  const float* points, const float* normals, std::int64_t numberOfPoints, Mesh& mesh)
{
  float low[3], high[3];
  for (int a = 0; a < 3; ++a)
  {
    low[a] = high[a] = points[a];
  }
  for (std::int64_t i = 0; i < 3 * numberOfPoints; i += 3)
  {
    for (int a = 0; a < 3; ++a)
    {
      const float v = points[i + a];
      low[a] = v < low[a] ? v : low[a];
      high[a] = v > high[a] ? v : high[a];
    }
  }
  float toStored[3];
  for (int a = 0; a < 3; ++a)
  {
    const float extent = high[a] - low[a];
    mesh.Offset[a] = low[a];
    mesh.Scale[a] = extent;
    toStored[a] = extent > 0.0f ? 65535.0f / extent : 0.0f;
  }
  // Rounded by adding a half and truncating (std::lround is a library call per
  // component).
  std::vector<std::uint8_t> packed(static_cast<std::size_t>(numberOfPoints) * PackedPointBytes);
  std::uint8_t* out = packed.data();
  for (std::int64_t i = 0; i < 3 * numberOfPoints; i += 3, out += PackedPointBytes)
  {
    std::uint16_t position[4] = { 0, 0, 0, 0 };
    std::int8_t normal[4] = { 0, 0, 0, 0 };
    for (int a = 0; a < 3; ++a)
    {
      position[a] = static_cast<std::uint16_t>((points[i + a] - low[a]) * toStored[a] + 0.5f);
      float n = 127.0f * normals[i + a];
      n = n > 127.0f ? 127.0f : n < -127.0f ? -127.0f : n;
      normal[a] = static_cast<std::int8_t>(n + (n >= 0.0f ? 0.5f : -0.5f));
    }
    std::memcpy(out, position, sizeof(position));
    std::memcpy(out + sizeof(position), normal, sizeof(normal));
  }
  return packed;
}

// The most points a chunk spans: 16-bit indices 0..65534 (WebGL2 always
// restarts primitives at 65535).
constexpr std::uint32_t ChunkPoints = 65535;
// More chunks than this (a mesh whose triangles jump across its points) are
// drawn with 32-bit indices instead: each chunk is a draw call.
constexpr std::size_t MaximumChunks = 4096;

// The triangles cut, in their order, into chunks that each span at most
// ChunkPoints points, and their indices rewritten as 16-bit offsets from their
// chunk's first point: half the index bytes to upload and fetch. The
// extraction writes each block's points together and its triangles after one
// another, so a chunk holds many blocks. False (nothing written) where that
// would take over MaximumChunks draws.
bool ChunkIndices(const std::uint32_t* triangles, std::int64_t numberOfTriangles,
  std::vector<Chunk>& chunks, std::vector<std::uint16_t>& indices)
{
  chunks.clear();
  Chunk chunk;
  std::uint32_t low = 0, high = 0;
  for (std::int64_t t = 0; t < numberOfTriangles; ++t)
  {
    const std::uint32_t* v = triangles + 3 * t;
    const std::uint32_t tl = std::min({ v[0], v[1], v[2] });
    const std::uint32_t th = std::max({ v[0], v[1], v[2] });
    if (th - tl >= ChunkPoints)
    {
      return false; // one triangle wider than a chunk
    }
    const std::uint32_t l = std::min(low, tl), h = std::max(high, th);
    if (chunk.Triangles > 0 && h - l < ChunkPoints)
    {
      low = l;
      high = h;
      ++chunk.Triangles;
      continue;
    }
    if (chunk.Triangles > 0)
    {
      chunk.FirstPoint = low;
      chunks.push_back(chunk);
      if (chunks.size() >= MaximumChunks)
      {
        return false;
      }
    }
    chunk.FirstTriangle = t;
    chunk.Triangles = 1;
    low = tl;
    high = th;
  }
  chunk.FirstPoint = low;
  chunks.push_back(chunk);
  indices.resize(3 * static_cast<std::size_t>(numberOfTriangles));
  for (const Chunk& c : chunks)
  {
    for (std::int64_t i = 3 * c.FirstTriangle; i < 3 * (c.FirstTriangle + c.Triangles); ++i)
    {
      indices[i] = static_cast<std::uint16_t>(triangles[i] - c.FirstPoint);
    }
  }
  return true;
}

// The vertex array's attributes pointed at `firstPoint` of the bound packed
// vertex buffer.
void PointAttributes(const GLApi::Functions& f, std::uint32_t firstPoint)
{
  const std::size_t at = static_cast<std::size_t>(firstPoint) * PackedPointBytes;
  f.VertexAttribPointer(
    0, 4, GL_UNSIGNED_SHORT, GL_TRUE, PackedPointBytes, reinterpret_cast<const void*>(at));
  f.VertexAttribPointer(
    1, 4, GL_BYTE, GL_TRUE, PackedPointBytes, reinterpret_cast<const void*>(at + 8));
}
} // namespace

struct MeshRenderer::Internals
{
  std::shared_ptr<const GLApi> GL;
  std::vector<std::unique_ptr<Mesh>> Meshes;
  ProgramCache Programs;
};

MeshRenderer::MeshRenderer(std::shared_ptr<const GLApi> gl)
  : Impl(new Internals)
{
  this->Impl->GL = std::move(gl);
}

MeshRenderer::~MeshRenderer() = default;

void MeshRenderer::Release()
{
  this->Impl->Meshes.clear();
  this->Impl->Programs.Clear();
}

int MeshRenderer::GetNumberOfMeshes() const
{
  return static_cast<int>(this->Impl->Meshes.size());
}

std::int64_t MeshRenderer::GetNumberOfTriangles(int slot) const
{
  const auto& meshes = this->Impl->Meshes;
  return slot >= 0 && slot < static_cast<int>(meshes.size()) && meshes[slot] ? meshes[slot]->Triangles
                                                                                 : 0;
}

void MeshRenderer::Clear(int slot)
{
  auto& meshes = this->Impl->Meshes;
  if (slot >= 0 && slot < static_cast<int>(meshes.size()))
  {
    meshes[slot].reset();
  }
}

void MeshRenderer::SetMesh(int slot, const float* points, const float* normals,
  std::int64_t numberOfPoints, const std::uint32_t* triangles, std::int64_t numberOfTriangles)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  if (slot < 0)
  {
    return;
  }
  if (slot >= static_cast<int>(impl.Meshes.size()))
  {
    impl.Meshes.resize(static_cast<std::size_t>(slot) + 1);
  }
  if (numberOfPoints == 0 || numberOfTriangles == 0)
  {
    impl.Meshes[slot].reset();
    return;
  }
  float color[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
  bool visible = true;
  if (impl.Meshes[slot])
  {
    std::copy(impl.Meshes[slot]->Color, impl.Meshes[slot]->Color + 4, color);
    visible = impl.Meshes[slot]->Visible;
  }
  std::unique_ptr<Mesh> mesh(new Mesh);
  std::copy(color, color + 4, mesh->Color);
  mesh->Visible = visible;
  ScopedGLState saved(gl, 0);
  const std::vector<std::uint8_t> packed = PackVertices(points, normals, numberOfPoints, *mesh);
  mesh->VertexArray = Name(gl, NameKind::VertexArray);
  mesh->Vertices = Name(gl, NameKind::Buffer);
  mesh->Indices = Name(gl, NameKind::Buffer);
  f.BindVertexArray(mesh->VertexArray.Get());
  f.BindBuffer(GL_ARRAY_BUFFER, mesh->Vertices.Get());
  f.BufferData(
    GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(packed.size()), packed.data(), GL_STATIC_DRAW);
  f.EnableVertexAttribArray(0);
  f.EnableVertexAttribArray(1);
  PointAttributes(f, 0);
  f.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh->Indices.Get());
  std::vector<std::uint16_t> shortIndices;
  if (ChunkIndices(triangles, numberOfTriangles, mesh->Chunks, shortIndices))
  {
    f.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(2 * shortIndices.size()),
      shortIndices.data(), GL_STATIC_DRAW);
  }
  else
  {
    mesh->Chunks.clear();
    f.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(12 * numberOfTriangles),
      triangles, GL_STATIC_DRAW);
  }
  f.BindVertexArray(0); // (the element buffer stays with the vertex array)
  mesh->Triangles = numberOfTriangles;
  impl.Meshes[slot] = std::move(mesh);
}

void MeshRenderer::SetLook(int slot, const float color[3], float opacity, bool visible)
{
  auto& meshes = this->Impl->Meshes;
  if (slot >= 0 && slot < static_cast<int>(meshes.size()) && meshes[slot])
  {
    std::copy(color, color + 3, meshes[slot]->Color);
    meshes[slot]->Color[3] = opacity;
    meshes[slot]->Visible = visible;
  }
}

bool MeshRenderer::Render(const IsosurfaceFrame& frame, const matrix4::Matrix& worldToView,
  const matrix4::Matrix& projection, std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  const std::string defines = "#define MEDISO_LIGHTS " + std::to_string(frame.LightsUsed()) + "\n";
  Program* program = impl.Programs.Get(gl, defines, shaders::Mesh_vs, shaders::Mesh_fs, error);
  if (!program)
  {
    error = "the mesh shaders do not build: " + error;
    return false;
  }
  ScopedGLState saved(gl, 0);
  program->Use();
  program->SetMatrix4("worldToView", worldToView.data());
  program->SetMatrix4("projection", projection.data());
  double normalToView[9];
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      normalToView[3 * r + c] = worldToView[4 * r + c]; // a rotation: its own inverse transpose
    }
  }
  program->SetMatrix3("normalToView", normalToView);
  program->Set("parallelProjection", frame.Parallel ? 1 : 0);
  SetLightingUniforms(*program, frame);
  f.Enable(GL_DEPTH_TEST);
  f.Disable(GL_CULL_FACE);
  // A mirrored placement (a reflection in worldToView) turns the triangles'
  // winding in the picture: counter-clockwise faces would then be the back
  // ones, and the two-sided shading would turn every normal away from the
  // viewer. The front faces are then the clockwise ones.
  const matrix4::Matrix& m = worldToView;
  const double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
    m[2] * (m[4] * m[9] - m[5] * m[8]);
  glFrontFace(det < 0.0 ? GL_CW : GL_CCW);
  for (int translucent = 0; translucent < 2; ++translucent)
  {
    SetSurfacePassBlending(gl, translucent != 0);
    for (const auto& mesh : impl.Meshes)
    {
      if (!mesh || !mesh->Visible || (mesh->Color[3] < 1.0f) != (translucent == 1))
      {
        continue;
      }
      program->Set4f("color", mesh->Color);
      program->Set3fv("positionOffset", 1, mesh->Offset);
      program->Set3fv("positionScale", 1, mesh->Scale);
      f.BindVertexArray(mesh->VertexArray.Get());
      if (mesh->Chunks.empty())
      {
        f.DrawElements(
          GL_TRIANGLES, static_cast<GLsizei>(3 * mesh->Triangles), GL_UNSIGNED_INT, nullptr);
        continue;
      }
      f.BindBuffer(GL_ARRAY_BUFFER, mesh->Vertices.Get());
      for (const Chunk& chunk : mesh->Chunks)
      {
        PointAttributes(f, chunk.FirstPoint);
        f.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * chunk.Triangles), GL_UNSIGNED_SHORT,
          reinterpret_cast<const void*>(static_cast<std::size_t>(6 * chunk.FirstTriangle)));
      }
    }
  }
  glFrontFace(GL_CCW); // WebGL's default, which the rest of the page's drawing takes
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "drawing the meshes failed: " + errors;
    return false;
  }
  return true;
}

} // namespace web
} // namespace mediso
