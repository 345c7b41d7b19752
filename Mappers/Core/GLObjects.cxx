// SPDX-License-Identifier: BSD-3-Clause
#include "GLObjects.h"

#include <algorithm>
#include <stdexcept>

namespace mediso
{
namespace glcore
{

std::string Compose(const std::string& source, const Hooks& hooks)
{
  std::string text = source;
  for (const auto& hook : hooks)
  {
    const std::string tag = "//MEDISO::" + hook.first;
    const std::size_t at = text.find(tag);
    if (at == std::string::npos)
    {
      // A hook that does not exist is a bug of the core, not of the input.
      throw std::logic_error("shader hook " + tag + " not found");
    }
    text.replace(at, tag.size(), hook.second);
  }
  return text;
}

Program::~Program()
{
  if (this->Id)
  {
    this->GL->F().DeleteProgram(this->Id);
  }
}

GLint Program::Location(const char* name)
{
  auto it = this->Locations.find(name);
  if (it == this->Locations.end())
  {
    it = this->Locations.emplace(name, this->GL->F().GetUniformLocation(this->Id, name)).first;
  }
  return it->second;
}

void Program::Set(const char* name, int v)
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    this->GL->F().Uniform1i(at, v);
  }
}

void Program::Set(const char* name, float v)
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    this->GL->F().Uniform1f(at, v);
  }
}

void Program::Set2i(const char* name, int x, int y)
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    this->GL->F().Uniform2i(at, x, y);
  }
}

void Program::Set3i(const char* name, const int v[3])
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    this->GL->F().Uniform3i(at, v[0], v[1], v[2]);
  }
}

void Program::Set2f(const char* name, float x, float y)
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    this->GL->F().Uniform2f(at, x, y);
  }
}

void Program::Set4f(const char* name, const float v[4])
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    this->GL->F().Uniform4f(at, v[0], v[1], v[2], v[3]);
  }
}

void Program::Set1iv(const char* name, int count, const int* v)
{
  const GLint at = this->Location(name);
  if (at >= 0 && count > 0)
  {
    this->GL->F().Uniform1iv(at, count, v);
  }
}

void Program::Set1uiv(const char* name, int count, const unsigned int* v)
{
  const GLint at = this->Location(name);
  if (at >= 0 && count > 0)
  {
    this->GL->F().Uniform1uiv(at, count, v);
  }
}

void Program::Set1fv(const char* name, int count, const float* v)
{
  const GLint at = this->Location(name);
  if (at >= 0 && count > 0)
  {
    this->GL->F().Uniform1fv(at, count, v);
  }
}

void Program::Set3fv(const char* name, int count, const float* v)
{
  const GLint at = this->Location(name);
  if (at >= 0 && count > 0)
  {
    this->GL->F().Uniform3fv(at, count, v);
  }
}

void Program::Set4fv(const char* name, int count, const float* v)
{
  const GLint at = this->Location(name);
  if (at >= 0 && count > 0)
  {
    this->GL->F().Uniform4fv(at, count, v);
  }
}

void Program::SetMatrix4(const char* name, const double m[16])
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    // Column-major for GL (transposing here: GL ES 2 and WebGL 1 refuse a
    // transposed upload, and it costs nothing).
    GLfloat values[16];
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        values[4 * c + r] = static_cast<GLfloat>(m[4 * r + c]);
      }
    }
    this->GL->F().UniformMatrix4fv(at, 1, GL_FALSE, values);
  }
}

void Program::SetMatrix3(const char* name, const double m[9])
{
  const GLint at = this->Location(name);
  if (at >= 0)
  {
    GLfloat values[9];
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        values[3 * c + r] = static_cast<GLfloat>(m[3 * r + c]);
      }
    }
    this->GL->F().UniformMatrix3fv(at, 1, GL_FALSE, values);
  }
}

namespace
{
std::string ShaderLog(const GLApi::Functions& f, GLuint shader)
{
  GLint length = 0;
  f.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  f.GetShaderInfoLog(shader, length, nullptr, &log[0]);
  return log.c_str();
}

GLuint CompileStage(const GLApi& gl, GLenum stage, const std::string& text, std::string& error)
{
  const GLApi::Functions& f = gl.F();
  const GLuint shader = f.CreateShader(stage);
  const GLchar* source = text.c_str();
  f.ShaderSource(shader, 1, &source, nullptr);
  f.CompileShader(shader);
  GLint ok = GL_FALSE;
  f.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok)
  {
    error = std::string(stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
      " shader does not compile: " + ShaderLog(f, shader);
    f.DeleteShader(shader);
    return 0;
  }
  return shader;
}
} // namespace

std::unique_ptr<Program> BuildProgram(const GLApi& gl, const std::string& defines,
  const std::string& vertex, const std::string& fragment, std::string& error)
{
  const GLApi::Functions& f = gl.F();
  const std::string head = gl.GetShaderPrelude() + defines;
  const GLuint vs = CompileStage(gl, GL_VERTEX_SHADER, head + vertex, error);
  if (!vs)
  {
    return nullptr;
  }
  const GLuint fs = CompileStage(gl, GL_FRAGMENT_SHADER, head + fragment, error);
  if (!fs)
  {
    f.DeleteShader(vs);
    return nullptr;
  }
  const GLuint id = f.CreateProgram();
  f.AttachShader(id, vs);
  f.AttachShader(id, fs);
  // Vertex inputs named vertexInputN take location N (the programs that have
  // attributes set their vertex arrays up so).
  for (int n = 0; n < 4; ++n)
  {
    const std::string name = "vertexInput" + std::to_string(n);
    f.BindAttribLocation(id, static_cast<GLuint>(n), name.c_str());
  }
  if (!gl.IsES())
  {
    // GLSL 1.50 has no layout locations for outputs: bind them by name.
    for (int n = 0; n < 4; ++n)
    {
      const std::string name = "fragOutput" + std::to_string(n);
      f.BindFragDataLocation(id, static_cast<GLuint>(n), name.c_str());
    }
  }
  f.LinkProgram(id);
  f.DeleteShader(vs); // flagged: freed with the program
  f.DeleteShader(fs);
  GLint ok = GL_FALSE;
  f.GetProgramiv(id, GL_LINK_STATUS, &ok);
  if (!ok)
  {
    GLint length = 0;
    f.GetProgramiv(id, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    f.GetProgramInfoLog(id, length, nullptr, &log[0]);
    error = "program does not link: " + std::string(log.c_str());
    f.DeleteProgram(id);
    return nullptr;
  }
  return std::unique_ptr<Program>(new Program(gl, id));
}

namespace
{
std::string ProgramKey(
  const std::string& defines, const std::string& vertex, const std::string& fragment)
{
  std::string key = defines;
  key += '\x01';
  key += vertex;
  key += '\x01';
  key += fragment;
  return key;
}
}

bool ProgramCache::Has(
  const std::string& defines, const std::string& vertex, const std::string& fragment) const
{
  return this->Programs.count(ProgramKey(defines, vertex, fragment)) > 0;
}

Program* ProgramCache::Get(const GLApi& gl, const std::string& defines, const std::string& vertex,
  const std::string& fragment, std::string& error)
{
  std::string key = ProgramKey(defines, vertex, fragment);
  auto it = this->Programs.find(key);
  if (it != this->Programs.end())
  {
    return it->second.get();
  }
  std::unique_ptr<Program> program = BuildProgram(gl, defines, vertex, fragment, error);
  if (!program)
  {
    return nullptr;
  }
  ++this->Builds;
  return this->Programs.emplace(std::move(key), std::move(program)).first->second.get();
}

Name::Name(const GLApi& gl, NameKind kind)
  : GL(&gl)
  , Kind(kind)
{
  const GLApi::Functions& f = gl.F();
  switch (kind)
  {
    case NameKind::Texture:
      f.GenTextures(1, &this->Id);
      break;
    case NameKind::Framebuffer:
      f.GenFramebuffers(1, &this->Id);
      break;
    case NameKind::Renderbuffer:
      f.GenRenderbuffers(1, &this->Id);
      break;
    case NameKind::Buffer:
      f.GenBuffers(1, &this->Id);
      break;
    case NameKind::VertexArray:
      f.GenVertexArrays(1, &this->Id);
      break;
  }
}

Name& Name::operator=(Name&& other) noexcept
{
  if (this != &other)
  {
    this->Reset();
    this->GL = other.GL;
    this->Kind = other.Kind;
    this->Id = other.Id;
    other.Id = 0;
  }
  return *this;
}

void Name::Reset()
{
  if (!this->Id)
  {
    return;
  }
  const GLApi::Functions& f = this->GL->F();
  switch (this->Kind)
  {
    case NameKind::Texture:
      f.DeleteTextures(1, &this->Id);
      break;
    case NameKind::Framebuffer:
      f.DeleteFramebuffers(1, &this->Id);
      break;
    case NameKind::Renderbuffer:
      f.DeleteRenderbuffers(1, &this->Id);
      break;
    case NameKind::Buffer:
      f.DeleteBuffers(1, &this->Id);
      break;
    case NameKind::VertexArray:
      f.DeleteVertexArrays(1, &this->Id);
      break;
  }
  this->Id = 0;
}

ScopedGLState::ScopedGLState(const GLApi& gl, int textureUnits)
  : GL(gl)
{
  const GLApi::Functions& f = gl.F();
  std::vector<GLenum> caps = { GL_DEPTH_TEST, GL_BLEND, GL_CULL_FACE, GL_SCISSOR_TEST,
    GL_STENCIL_TEST, GL_RASTERIZER_DISCARD, GL_POLYGON_OFFSET_FILL, GL_SAMPLE_ALPHA_TO_COVERAGE };
  if (!gl.IsES())
  {
    caps.push_back(GL_PROGRAM_POINT_SIZE);
  }
  for (GLenum cap : caps)
  {
    this->Enables.push_back({ cap, f.IsEnabled(cap) });
  }
  f.GetIntegerv(GL_VIEWPORT, this->Viewport);
  f.GetIntegerv(GL_CURRENT_PROGRAM, &this->Program);
  f.GetIntegerv(GL_VERTEX_ARRAY_BINDING, &this->VertexArray);
  f.GetIntegerv(GL_ARRAY_BUFFER_BINDING, &this->ArrayBuffer);
  f.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &this->DrawFramebuffer);
  f.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &this->ReadFramebuffer);
  f.GetIntegerv(GL_RENDERBUFFER_BINDING, &this->Renderbuffer);
  f.GetIntegerv(GL_ACTIVE_TEXTURE, &this->ActiveTexture);
  f.GetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &this->PackBuffer);
  f.GetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &this->UnpackBuffer);
  f.GetIntegerv(GL_PACK_ALIGNMENT, &this->PackAlignment);
  f.GetIntegerv(GL_UNPACK_ALIGNMENT, &this->UnpackAlignment);
  f.GetIntegerv(GL_UNPACK_ROW_LENGTH, &this->UnpackRowLength);
  f.GetIntegerv(GL_UNPACK_IMAGE_HEIGHT, &this->UnpackImageHeight);
  f.GetIntegerv(GL_BLEND_SRC_RGB, &this->BlendSrcRGB);
  f.GetIntegerv(GL_BLEND_DST_RGB, &this->BlendDstRGB);
  f.GetIntegerv(GL_BLEND_SRC_ALPHA, &this->BlendSrcAlpha);
  f.GetIntegerv(GL_BLEND_DST_ALPHA, &this->BlendDstAlpha);
  f.GetIntegerv(GL_BLEND_EQUATION_RGB, &this->BlendEquationRGB);
  f.GetIntegerv(GL_BLEND_EQUATION_ALPHA, &this->BlendEquationAlpha);
  f.GetIntegerv(GL_DEPTH_FUNC, &this->DepthFunc);
  f.GetBooleanv(GL_DEPTH_WRITEMASK, &this->DepthMask);
  f.GetBooleanv(GL_COLOR_WRITEMASK, this->ColorMask);
  this->Units.resize(static_cast<std::size_t>(std::max(textureUnits, 0)));
  for (std::size_t u = 0; u < this->Units.size(); ++u)
  {
    f.ActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(u));
    f.GetIntegerv(GL_TEXTURE_BINDING_2D, &this->Units[u].Texture2D);
    f.GetIntegerv(GL_TEXTURE_BINDING_3D, &this->Units[u].Texture3D);
    f.GetIntegerv(GL_SAMPLER_BINDING, &this->Units[u].Sampler);
  }
  f.ActiveTexture(static_cast<GLenum>(this->ActiveTexture));
  // Pixel transfers go to and from client memory while the core runs.
  if (this->PackBuffer)
  {
    f.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  }
  if (this->UnpackBuffer)
  {
    f.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  }
}

ScopedGLState::~ScopedGLState()
{
  const GLApi::Functions& f = this->GL.F();
  for (std::size_t u = 0; u < this->Units.size(); ++u)
  {
    f.ActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(u));
    f.BindTexture(GL_TEXTURE_2D, static_cast<GLuint>(this->Units[u].Texture2D));
    f.BindTexture(GL_TEXTURE_3D, static_cast<GLuint>(this->Units[u].Texture3D));
    f.BindSampler(static_cast<GLuint>(u), static_cast<GLuint>(this->Units[u].Sampler));
  }
  f.ActiveTexture(static_cast<GLenum>(this->ActiveTexture));
  for (const Enable& e : this->Enables)
  {
    if (e.On)
    {
      f.Enable(e.Cap);
    }
    else
    {
      f.Disable(e.Cap);
    }
  }
  f.Viewport(this->Viewport[0], this->Viewport[1], this->Viewport[2], this->Viewport[3]);
  f.UseProgram(static_cast<GLuint>(this->Program));
  f.BindVertexArray(static_cast<GLuint>(this->VertexArray));
  f.BindBuffer(GL_ARRAY_BUFFER, static_cast<GLuint>(this->ArrayBuffer));
  f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(this->DrawFramebuffer));
  f.BindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(this->ReadFramebuffer));
  f.BindRenderbuffer(GL_RENDERBUFFER, static_cast<GLuint>(this->Renderbuffer));
  f.BindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(this->PackBuffer));
  f.BindBuffer(GL_PIXEL_UNPACK_BUFFER, static_cast<GLuint>(this->UnpackBuffer));
  f.PixelStorei(GL_PACK_ALIGNMENT, this->PackAlignment);
  f.PixelStorei(GL_UNPACK_ALIGNMENT, this->UnpackAlignment);
  f.PixelStorei(GL_UNPACK_ROW_LENGTH, this->UnpackRowLength);
  f.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, this->UnpackImageHeight);
  f.BlendFuncSeparate(static_cast<GLenum>(this->BlendSrcRGB), static_cast<GLenum>(this->BlendDstRGB),
    static_cast<GLenum>(this->BlendSrcAlpha), static_cast<GLenum>(this->BlendDstAlpha));
  f.BlendEquationSeparate(
    static_cast<GLenum>(this->BlendEquationRGB), static_cast<GLenum>(this->BlendEquationAlpha));
  f.DepthFunc(static_cast<GLenum>(this->DepthFunc));
  f.DepthMask(this->DepthMask);
  f.ColorMask(this->ColorMask[0], this->ColorMask[1], this->ColorMask[2], this->ColorMask[3]);
}

void SetNearest(const GLApi& gl, GLenum target)
{
  const GLApi::Functions& f = gl.F();
  f.TexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  f.TexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  f.TexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  f.TexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (target == GL_TEXTURE_3D)
  {
    f.TexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  }
  f.TexParameteri(target, GL_TEXTURE_BASE_LEVEL, 0);
  f.TexParameteri(target, GL_TEXTURE_MAX_LEVEL, 0);
}

void SetCountingPassState(const GLApi& gl)
{
  const GLApi::Functions& f = gl.F();
  for (GLenum cap :
    { GL_DEPTH_TEST, GL_BLEND, GL_SCISSOR_TEST, GL_STENCIL_TEST, GL_CULL_FACE, GL_RASTERIZER_DISCARD })
  {
    f.Disable(cap);
  }
  f.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

void SetSurfacePassBlending(const GLApi& gl, bool translucent)
{
  const GLApi::Functions& f = gl.F();
  if (translucent)
  {
    f.Enable(GL_BLEND);
    f.BlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
    f.BlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    f.DepthMask(GL_FALSE);
  }
  else
  {
    f.Disable(GL_BLEND);
    f.DepthMask(GL_TRUE);
  }
}

std::string FramebufferProblem(const GLApi& gl)
{
  const GLenum status = gl.F().CheckFramebufferStatus(GL_DRAW_FRAMEBUFFER);
  switch (status)
  {
    case GL_FRAMEBUFFER_COMPLETE:
      return "";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT:
      return "incomplete attachment";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
      return "missing attachment";
    case GL_FRAMEBUFFER_UNSUPPORTED:
      return "unsupported format combination";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE:
      return "incomplete multisample";
    default:
      return "status " + std::to_string(status);
  }
}

} // namespace glcore
} // namespace mediso
