// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file MeshRenderer.h
 * @brief Triangle meshes on WebGL2 for the web page: the CPU path's surfaces
 * (the BlockLOD core's triangles) and the surfaces the server makes.
 *
 * Each mesh is uploaded once (positions, normals, 32-bit indices) and drawn
 * with Phong shading under the same lights and material as the GPU path's
 * isosurfaces, opaque meshes first, then translucent ones blended over them
 * (premultiplied, no depth writes). It uses the GPU core's GL table and
 * program composition (GLApi, glcore), so it runs where the core runs.
 */
#ifndef MedicalIsosurfaces_MeshRenderer_h
#define MedicalIsosurfaces_MeshRenderer_h

#include "IsosurfaceFrame.h"
#include "Matrix4.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace mediso
{
class GLApi;

namespace web
{

class MeshRenderer
{
public:
  explicit MeshRenderer(std::shared_ptr<const GLApi> gl);
  ~MeshRenderer();

  /// Replaces mesh `slot` (created as needed): `points` and `normals` 3 floats each per point,
  /// `triangles` 3 indices each. Empty arrays clear the slot.
  void SetMesh(int slot, const float* points, const float* normals, std::int64_t numberOfPoints,
    const std::uint32_t* triangles, std::int64_t numberOfTriangles);
  void SetLook(int slot, const float color[3], float opacity, bool visible);
  void Clear(int slot);
  /// Slots in use.
  int GetNumberOfMeshes() const;
  std::int64_t GetNumberOfTriangles(int slot) const;

  /// Draws every visible mesh (model space `modelToWorld`) for `frame`'s lights and material,
  /// `worldToView` and projection, into the bound framebuffer with depth testing.
  bool Render(const IsosurfaceFrame& frame, const matrix4::Matrix& worldToView,
    const matrix4::Matrix& projection, std::string& error);

  void Release();

private:
  struct Internals;
  std::unique_ptr<Internals> Impl;
};

} // namespace web
} // namespace mediso

#endif
