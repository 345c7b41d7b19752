// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file GLObjects.h
 * @brief Small helpers of the GPU core (private): programs composed from the
 * shared GLSL, owned GL names, and the scoped save/restore of GL state.
 *
 * Shader composition has one mechanism: a shader is the context's prelude
 * (GLApi::GetShaderPrelude()), then the variant's `#define`s, then a source
 * file from Shaders/ whose `//MEDISO::Name` lines are replaced by named
 * snippets (the value type's crossing test, the pyramid's levels, ...).
 * Programs are compiled once per variant; the variant key is the composed
 * text itself, so two variants can never share a program by accident.
 *
 * ScopedGLState saves, at construction, every piece of context state the
 * core's passes change (enables, depth/blend/colour state, viewport, bound
 * program, vertex array, buffers, framebuffers, pixel store, and the
 * texture/sampler bindings of the units the core binds) and puts it back at
 * destruction, so that a host's own state tracking (VTK's vtkOpenGLState,
 * WebGL's) stays true.
 */
#ifndef MedicalIsosurfaces_GLObjects_h
#define MedicalIsosurfaces_GLObjects_h

#include "GLApiFunctions.h"

#include <cstdint>

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mediso
{
namespace glcore
{

/// A named snippet put in place of a `//MEDISO::Name` line.
using Hooks = std::vector<std::pair<std::string, std::string>>;

/// Source text with the hooks substituted (every hook line must exist once).
std::string Compose(const std::string& source, const Hooks& hooks);

/// A linked program with a cache of uniform locations.
class Program
{
public:
  Program(const GLApi& gl, GLuint id)
    : GL(&gl)
    , Id(id)
  {
  }
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  GLuint GetId() const { return this->Id; }
  void Use() const { this->GL->F().UseProgram(this->Id); }
  /// Location of a uniform (-1 when the program has no such active uniform).
  GLint Location(const char* name);

  void Set(const char* name, int v);
  void Set(const char* name, float v);
  void Set2i(const char* name, int x, int y);
  void Set3i(const char* name, const int v[3]);
  void Set2f(const char* name, float x, float y);
  void Set4f(const char* name, const float v[4]);
  void Set1iv(const char* name, int count, const int* v);
  void Set1uiv(const char* name, int count, const unsigned int* v);
  void Set1fv(const char* name, int count, const float* v);
  void Set3fv(const char* name, int count, const float* v);
  void Set4fv(const char* name, int count, const float* v);
  /// A 4x4 (3x3) matrix given row-major with column vectors (VTK's convention).
  void SetMatrix4(const char* name, const double m[16]);
  void SetMatrix3(const char* name, const double m[9]);

private:
  const GLApi* GL;
  GLuint Id;
  std::map<std::string, GLint> Locations;
};

/**
 * Compiles and links a program from a vertex and a fragment shader (each
 * already composed; the prelude and `defines` are put in front). Vertex
 * inputs named vertexInputN get location N, fragment outputs named
 * fragOutputN location N. Returns null, with the compiler's log in @a error,
 * when it does not build.
 */
std::unique_ptr<Program> BuildProgram(const GLApi& gl, const std::string& defines,
  const std::string& vertex, const std::string& fragment, std::string& error);

/// Programs by variant (the composed sources): built on first use.
class ProgramCache
{
public:
  /// The program of this variant, built if needed; null (and error) when it does not build.
  Program* Get(const GLApi& gl, const std::string& defines, const std::string& vertex,
    const std::string& fragment, std::string& error);
  /// Whether this variant is built already (Get() would compile nothing).
  bool Has(
    const std::string& defines, const std::string& vertex, const std::string& fragment) const;
  void Clear() { this->Programs.clear(); }
  /// Programs this cache has built so far (a variant cleared and asked for again counts again):
  /// the difference over a frame is what it compiled, one-off work a host's frame-time model
  /// keeps apart from the drawing.
  std::uint64_t GetBuilds() const { return this->Builds; }

private:
  std::map<std::string, std::unique_ptr<Program>> Programs;
  std::uint64_t Builds = 0;
};

/// A GL object name with its deleter.
enum class NameKind
{
  Texture,
  Framebuffer,
  Renderbuffer,
  Buffer,
  VertexArray
};

class Name
{
public:
  Name() = default;
  Name(const GLApi& gl, NameKind kind);
  ~Name() { this->Reset(); }
  Name(const Name&) = delete;
  Name& operator=(const Name&) = delete;
  Name(Name&& other) noexcept { *this = std::move(other); }
  Name& operator=(Name&& other) noexcept;

  GLuint Get() const { return this->Id; }
  explicit operator bool() const { return this->Id != 0; }
  void Reset();

private:
  const GLApi* GL = nullptr;
  NameKind Kind = NameKind::Texture;
  GLuint Id = 0;
};

/// Saves the state the core changes; restores it when destroyed.
class ScopedGLState
{
public:
  /// `textureUnits`: the units (0-based) whose 2D/3D texture and sampler bindings to save.
  ScopedGLState(const GLApi& gl, int textureUnits);
  ~ScopedGLState();
  ScopedGLState(const ScopedGLState&) = delete;
  ScopedGLState& operator=(const ScopedGLState&) = delete;

  /// Puts the saved depth function back now (a pass that changed it is over).
  void RestoreDepthFunc() const { this->GL.F().DepthFunc(static_cast<GLenum>(this->DepthFunc)); }

private:
  const GLApi& GL;
  struct Enable
  {
    GLenum Cap;
    GLboolean On;
  };
  std::vector<Enable> Enables;
  GLint Viewport[4] = { 0, 0, 0, 0 };
  GLint Program = 0, VertexArray = 0, ArrayBuffer = 0, DrawFramebuffer = 0, ReadFramebuffer = 0;
  GLint Renderbuffer = 0, ActiveTexture = 0, PackBuffer = 0, UnpackBuffer = 0;
  GLint PackAlignment = 4, UnpackAlignment = 4, UnpackRowLength = 0, UnpackImageHeight = 0;
  GLint BlendSrcRGB = 0, BlendDstRGB = 0, BlendSrcAlpha = 0, BlendDstAlpha = 0;
  GLint BlendEquationRGB = 0, BlendEquationAlpha = 0, DepthFunc = 0;
  GLboolean DepthMask = GL_TRUE;
  GLboolean ColorMask[4] = { GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE };
  struct Unit
  {
    GLint Texture2D, Texture3D, Sampler;
  };
  std::vector<Unit> Units;
};

/// Binds `texture` (a `target` texture) to `unit` with no sampler object.
inline void BindTextureUnit(const GLApi& gl, int unit, GLenum target, GLuint texture)
{
  gl.F().ActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  gl.F().BindTexture(target, texture);
  gl.F().BindSampler(static_cast<GLuint>(unit), 0);
}

/// Nearest filtering, clamped: the only sampling the core uses (texelFetch).
void SetNearest(const GLApi& gl, GLenum target);

/// The state of the core's counting passes (the probe, the pyramid's levels): every fragment
/// drawn is written as it is: no depth, stencil or scissor test, no blending or culling, the
/// rasteriser on, every colour channel. Call it inside a ScopedGLState.
void SetCountingPassState(const GLApi& gl);

/// Blending and depth writes of one of the two surface passes: opaque (no blending, depth
/// written) or translucent (premultiplied colours composited "over", depth tested only, so
/// that translucent surfaces never hide what lies behind them). Call it inside a ScopedGLState.
void SetSurfacePassBlending(const GLApi& gl, bool translucent);

/// "" when the bound draw framebuffer is complete, else why not.
std::string FramebufferProblem(const GLApi& gl);

} // namespace glcore
} // namespace mediso

#endif
