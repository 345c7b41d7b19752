// SPDX-License-Identifier: BSD-3-Clause
#include "GLApiFunctions.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace mediso
{
namespace
{
const char* ErrorName(GLenum err)
{
  switch (err)
  {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    default:
      return "unknown OpenGL error";
  }
}

std::string String(const GLApi::Functions& f, GLenum name)
{
  const GLubyte* s = f.GetString(name);
  return s ? reinterpret_cast<const char*>(s) : "";
}

// "OpenGL ES 3.2 Mesa ...", "OpenGL ES 3.0 (WebGL 2.0 ...)" or "4.5 (Core Profile) Mesa ...".
bool ParseVersion(const std::string& version, bool& es, int& major, int& minor)
{
  const char* prefix = "OpenGL ES";
  es = version.compare(0, std::strlen(prefix), prefix) == 0;
  std::size_t at = es ? std::strlen(prefix) : 0;
  while (at < version.size() && !(version[at] >= '0' && version[at] <= '9'))
  {
    ++at;
  }
  return std::sscanf(version.c_str() + at, "%d.%d", &major, &minor) == 2;
}
} // namespace

GLApi::GLApi()
  : Table(new Functions)
{
}

GLApi::~GLApi() = default;

std::shared_ptr<GLApi> GLApi::Load(ProcLookup lookup, void* user, std::string& error)
{
  std::shared_ptr<GLApi> api(new GLApi);
  Functions& f = *api->Table;
  std::string missing;
#define MEDISO_GL_LOAD(name)                                                                       \
  f.name = reinterpret_cast<decltype(f.name)>(lookup("gl" #name, user));                           \
  if (!f.name)                                                                                     \
  {                                                                                                \
    missing += (missing.empty() ? "gl" : ", gl") + std::string(#name);                             \
  }
  MEDISO_GL_FUNCTIONS(MEDISO_GL_LOAD)
#undef MEDISO_GL_LOAD
  if (!f.GetString || !f.GetIntegerv)
  {
    error = "the OpenGL functions cannot be found (" + missing + ")";
    return nullptr;
  }
  api->Version = String(f, GL_VERSION);
  api->Renderer = String(f, GL_RENDERER);
  api->Vendor = String(f, GL_VENDOR);
  api->ShadingLanguage = String(f, GL_SHADING_LANGUAGE_VERSION);
  if (api->Version.empty())
  {
    error = "no current OpenGL context (GL_VERSION is empty)";
    return nullptr;
  }
  if (!ParseVersion(api->Version, api->ES, api->Major, api->Minor))
  {
    error = "cannot read the OpenGL version \"" + api->Version + "\"";
    return nullptr;
  }
  const int version = 10 * api->Major + api->Minor;
  if (api->ES ? version < 30 : version < 32)
  {
    error = "OpenGL " + api->Version + " is too old: the GPU path needs OpenGL 3.2 or OpenGL ES 3.0";
    return nullptr;
  }
  if (!missing.empty())
  {
    error = "OpenGL " + api->Version + " lacks " + missing;
    return nullptr;
  }
  if (!api->ES)
  {
#define MEDISO_GL_LOAD_DESKTOP(name)                                                               \
  f.name = reinterpret_cast<decltype(f.name)>(lookup("gl" #name, user));                           \
  if (!f.name)                                                                                     \
  {                                                                                                \
    error = "OpenGL " + api->Version + " lacks gl" #name;                                          \
    return nullptr;                                                                                \
  }
    MEDISO_GL_DESKTOP_FUNCTIONS(MEDISO_GL_LOAD_DESKTOP)
#undef MEDISO_GL_LOAD_DESKTOP
  }

  api->TakeErrors();
  f.GetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &api->Max3DTextureSize);
  f.GetIntegerv(GL_MAX_TEXTURE_SIZE, &api->MaxTextureSize);
  f.GetIntegerv(GL_MAX_VERTEX_TEXTURE_IMAGE_UNITS, &api->MaxVertexTextureUnits);
  f.GetIntegerv(GL_MAX_COMBINED_TEXTURE_IMAGE_UNITS, &api->MaxCombinedTextureUnits);
  f.GetIntegerv(GL_MAX_DRAW_BUFFERS, &api->MaxDrawBuffers);
  f.GetIntegerv(GL_MAX_COLOR_ATTACHMENTS, &api->MaxColorAttachments);
  GLfloat sizes[2] = { 1.0f, 1.0f };
  if (api->ES)
  {
    f.GetFloatv(GL_ALIASED_POINT_SIZE_RANGE, sizes);
    api->PointSizeGranularity = 1.0f; // not queryable on GL ES: assume the coarsest
  }
  else
  {
    GLint profile = 0;
    f.GetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    api->CoreProfile = (profile & 0x1) != 0; // GL_CONTEXT_CORE_PROFILE_BIT
    f.GetFloatv(GL_POINT_SIZE_RANGE, sizes);
    GLfloat granularity = 1.0f;
    f.GetFloatv(GL_POINT_SIZE_GRANULARITY, &granularity);
    api->PointSizeGranularity = std::max(0.0f, std::min(granularity, 1.0f));
  }
  // The extensions: conservative depth (desktop GL), and the two that tell the device's memory.
  bool nvxMemory = false, atiMemory = false;
  GLint count = 0;
  f.GetIntegerv(GL_NUM_EXTENSIONS, &count);
  for (GLint e = 0; e < count; ++e)
  {
    const GLubyte* name = f.GetStringi(GL_EXTENSIONS, static_cast<GLuint>(e));
    const char* text = reinterpret_cast<const char*>(name);
    if (!name)
    {
      continue;
    }
    api->ConservativeDepth |= !api->ES && std::strcmp(text, "GL_ARB_conservative_depth") == 0;
    nvxMemory |= std::strcmp(text, "GL_NVX_gpu_memory_info") == 0;
    atiMemory |= std::strcmp(text, "GL_ATI_meminfo") == 0;
  }
  // Both report kilobytes (GL_ATI_meminfo: four values, the first the pool's total free memory).
  const GLenum dedicatedNVX = 0x9047;   // GL_GPU_MEMORY_INFO_DEDICATED_VIDMEM_NVX
  const GLenum textureFreeATI = 0x87FC; // GL_TEXTURE_FREE_MEMORY_ATI
  GLint kilobytes[4] = { 0, 0, 0, 0 };
  if (nvxMemory)
  {
    f.GetIntegerv(dedicatedNVX, kilobytes);
  }
  else if (atiMemory)
  {
    f.GetIntegerv(textureFreeATI, kilobytes);
  }
  api->DeviceMemoryBytes = static_cast<std::uint64_t>(std::max<GLint>(0, kilobytes[0])) * 1024;
  api->MaxPointSize = sizes[1];
  const std::string errors = api->TakeErrors();
  if (!errors.empty())
  {
    error = "querying the limits of OpenGL " + api->Version + " failed: " + errors;
    return nullptr;
  }

  if (api->ES)
  {
    api->Prelude = "#version 300 es\n"
                   "precision highp float;\n"
                   "precision highp int;\n"
                   "precision highp sampler2D;\n"
                   "precision highp sampler3D;\n"
                   "precision highp isampler3D;\n"
                   "precision highp usampler3D;\n"
                   "precision highp usampler2D;\n"
                   "#define MEDISO_GLSL_ES 1\n"
                   "#define MEDISO_OUTPUT(n) layout(location = n) out\n";
  }
  else
  {
    api->Prelude = "#version 150\n"
                   "#define MEDISO_OUTPUT(n) out\n";
  }
  return api;
}

std::string GLApi::Describe() const
{
  return (this->ES ? "" : "OpenGL ") + this->Version + " (" + this->Renderer + ")";
}

std::string GLApi::TakeErrors() const
{
  std::string errors;
  for (int n = 0; n < 16; ++n)
  {
    const GLenum err = this->Table->GetError();
    if (err == GL_NO_ERROR)
    {
      break;
    }
    errors += (errors.empty() ? "" : ", ") + std::string(ErrorName(err));
  }
  return errors;
}

} // namespace mediso
