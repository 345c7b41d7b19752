// SPDX-License-Identifier: BSD-3-Clause
#include "MeshRenderer.h"

#include "GLApiFunctions.h"
#include "GLObjects.h"
#include "Lighting.h"
#include "WebShaders.h"

#include <algorithm>

namespace mediso
{
namespace web
{
namespace
{
using namespace glcore;

struct Mesh
{
  Name VertexArray, Points, Normals, Indices;
  std::int64_t Triangles = 0;
  float Color[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
  bool Visible = true;
};
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
  mesh->VertexArray = Name(gl, NameKind::VertexArray);
  mesh->Points = Name(gl, NameKind::Buffer);
  mesh->Normals = Name(gl, NameKind::Buffer);
  mesh->Indices = Name(gl, NameKind::Buffer);
  f.BindVertexArray(mesh->VertexArray.Get());
  f.BindBuffer(GL_ARRAY_BUFFER, mesh->Points.Get());
  f.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(12 * numberOfPoints), points, GL_STATIC_DRAW);
  f.EnableVertexAttribArray(0);
  f.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  f.BindBuffer(GL_ARRAY_BUFFER, mesh->Normals.Get());
  f.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(12 * numberOfPoints), normals, GL_STATIC_DRAW);
  f.EnableVertexAttribArray(1);
  f.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  f.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh->Indices.Get());
  f.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(12 * numberOfTriangles), triangles,
    GL_STATIC_DRAW);
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
      f.BindVertexArray(mesh->VertexArray.Get());
      f.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * mesh->Triangles), GL_UNSIGNED_INT, nullptr);
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
