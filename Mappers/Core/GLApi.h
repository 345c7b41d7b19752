// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file GLApi.h
 * @brief The OpenGL entry points and facts of a context, for the GPU core (no VTK, no GL header).
 *
 * The GPU core is written once for the common subset of OpenGL 3.2 core and
 * OpenGL ES 3.0 (= WebGL2): no geometry or compute shaders, no storage
 * buffers, no gl_Layer, no interface blocks between stages. A host makes its
 * context current and calls GLApi::Load() with a lookup of functions by name
 * (see GLFunctionList.h); the GLApi then holds the function table, whether
 * the context is desktop GL or GL ES, the GLSL prelude for it (`#version
 * 150`, or `#version 300 es` with highp defaults) and the limits the core
 * checks (texture sizes, vertex texture units, point sizes). Every core
 * object shares one GLApi and must be used with a context of the same share
 * group current.
 *
 * Load() fails, with a reason, on a context older than OpenGL 3.2 or
 * OpenGL ES 3.0 or one that lacks a required function: the caller then knows
 * the GPU path cannot run there and says so.
 */
#ifndef MedicalIsosurfaces_GLApi_h
#define MedicalIsosurfaces_GLApi_h

#include <cstdint>
#include <memory>
#include <string>

namespace mediso
{

class GLApi
{
public:
  /// Looks up an OpenGL function by its name ("glTexImage3D"); null when absent.
  using ProcLookup = void* (*)(const char* name, void* user);

  /**
   * The table and facts of the current context. Returns null, with a reason
   * in @a error, when the context is not OpenGL >= 3.2 or OpenGL ES >= 3.0,
   * or a required function is missing.
   */
  static std::shared_ptr<GLApi> Load(ProcLookup lookup, void* user, std::string& error);

  ~GLApi();
  GLApi(const GLApi&) = delete;
  GLApi& operator=(const GLApi&) = delete;

  /// OpenGL ES (or WebGL2) rather than desktop OpenGL.
  bool IsES() const { return this->ES; }
  int GetMajorVersion() const { return this->Major; }
  int GetMinorVersion() const { return this->Minor; }
  /// GL_RENDERER, GL_VERSION and GL_VENDOR as the context reports them.
  const std::string& GetRenderer() const { return this->Renderer; }
  const std::string& GetVersion() const { return this->Version; }
  const std::string& GetVendor() const { return this->Vendor; }
  const std::string& GetShadingLanguageVersion() const { return this->ShadingLanguage; }
  /// A desktop core-profile context (false on GL ES and compatibility contexts).
  bool IsCoreProfile() const { return this->CoreProfile; }

  ///@{
  /// Limits of the context.
  int GetMax3DTextureSize() const { return this->Max3DTextureSize; }
  int GetMaxTextureSize() const { return this->MaxTextureSize; }
  int GetMaxVertexTextureUnits() const { return this->MaxVertexTextureUnits; }
  int GetMaxCombinedTextureUnits() const { return this->MaxCombinedTextureUnits; }
  int GetMaxDrawBuffers() const { return this->MaxDrawBuffers; }
  int GetMaxColorAttachments() const { return this->MaxColorAttachments; }
  float GetMaxPointSize() const { return this->MaxPointSize; }
  /// Step of point sizes (desktop GL reports it; assumed 1 pixel on GL ES).
  float GetPointSizeGranularity() const { return this->PointSizeGranularity; }
  ///@}

  /// Desktop OpenGL with GL_ARB_conservative_depth.
  bool HasConservativeDepth() const { return this->ConservativeDepth; }

  /**
   * The device's memory in bytes where the context can tell (0 where not):
   * GL_NVX_gpu_memory_info's dedicated video memory, else GL_ATI_meminfo's
   * free texture memory at context creation. Neither OpenGL ES nor WebGL2
   * has a query of its own, and Mesa's llvmpipe exposes neither extension.
   * IsosurfaceScene's default GPU budget is half of it.
   */
  std::uint64_t GetDeviceMemoryBytes() const { return this->DeviceMemoryBytes; }

  /**
   * The first lines of every shader the core compiles for this context:
   * `#version 150`, or `#version 300 es` with highp default precisions;
   * then MEDISO_GLSL_ES where it is GL ES, and the MEDISO_OUTPUT(n) macro
   * that declares fragment output n (a layout location on GL ES; on desktop
   * GLSL 1.50 the program binds output fragOutputN to N before linking).
   */
  const std::string& GetShaderPrelude() const { return this->Prelude; }

  /// One line: "OpenGL ES 3.2 Mesa 22.3.6 (llvmpipe ...)".
  std::string Describe() const;

  /// Fetches and clears the error flags: "" when there was none.
  std::string TakeErrors() const;

  /// The function table (defined in GLApiFunctions.h, private to the core).
  struct Functions;
  const Functions& F() const { return *this->Table; }

private:
  GLApi();

  std::unique_ptr<Functions> Table;
  bool ES = false;
  int Major = 0;
  int Minor = 0;
  std::string Renderer, Version, Vendor, ShadingLanguage, Prelude;
  bool CoreProfile = false;
  int Max3DTextureSize = 0;
  int MaxTextureSize = 0;
  int MaxVertexTextureUnits = 0;
  int MaxCombinedTextureUnits = 0;
  int MaxDrawBuffers = 0;
  int MaxColorAttachments = 0;
  float MaxPointSize = 1.0f;
  float PointSizeGranularity = 1.0f;
  bool ConservativeDepth = false;
  std::uint64_t DeviceMemoryBytes = 0;
};

} // namespace mediso

#endif
