// SPDX-License-Identifier: BSD-3-Clause
#include "HeadlessContext.h"

#include "GLApi.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace mediso
{
namespace headless
{
namespace
{
std::string EGLErrorText(EGLint error)
{
  switch (error)
  {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
    {
      char text[32];
      std::snprintf(text, sizeof(text), "EGL error 0x%x", static_cast<unsigned>(error));
      return text;
    }
  }
}

bool HasExtension(const char* list, const char* name)
{
  if (!list)
  {
    return false;
  }
  const std::size_t length = std::strlen(name);
  for (const char* at = std::strstr(list, name); at; at = std::strstr(at + 1, name))
  {
    if ((at == list || at[-1] == ' ') && (at[length] == ' ' || at[length] == '\0'))
    {
      return true;
    }
  }
  return false;
}

void* LookUp(const char* name, void*)
{
  return reinterpret_cast<void*>(eglGetProcAddress(name));
}

struct Candidate
{
  std::string Name;
  EGLDisplay Display;
};

// The displays to try, in order (see the header).
std::vector<Candidate> Displays(const std::string& wanted)
{
  std::vector<Candidate> displays;
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
    eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if ((wanted.empty() || wanted == "surfaceless") && getPlatformDisplay &&
    HasExtension(clientExtensions, "EGL_MESA_platform_surfaceless"))
  {
    displays.push_back({ "surfaceless",
      getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr) });
  }
  auto queryDevices =
    reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  if ((wanted.empty() || wanted == "device") && getPlatformDisplay && queryDevices &&
    HasExtension(clientExtensions, "EGL_EXT_platform_device"))
  {
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (queryDevices(16, devices, &count))
    {
      for (EGLint d = 0; d < count; ++d)
      {
        displays.push_back({ "device " + std::to_string(d),
          getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[d], nullptr) });
      }
    }
  }
  if (wanted.empty() || wanted == "default")
  {
    displays.push_back({ "default", eglGetDisplay(EGL_DEFAULT_DISPLAY) });
  }
  return displays;
}
} // namespace

struct HeadlessContext::Handles
{
  EGLDisplay Display = EGL_NO_DISPLAY;
  EGLContext Context = EGL_NO_CONTEXT;
};

std::unique_ptr<HeadlessContext> HeadlessContext::Create(ContextApi api, std::string& error)
{
  const char* env = std::getenv("MEDISO_EGL_PLATFORM");
  const std::string wanted = env ? env : "";
  if (!wanted.empty() && wanted != "surfaceless" && wanted != "device" && wanted != "default")
  {
    error = "MEDISO_EGL_PLATFORM must be surfaceless, device or default, not \"" + wanted + "\"";
    return nullptr;
  }
  std::string reasons;
  for (const Candidate& candidate : Displays(wanted))
  {
    auto fail = [&](const std::string& why)
    {
      reasons += (reasons.empty() ? "" : "; ") + candidate.Name + ": " + why;
    };
    if (candidate.Display == EGL_NO_DISPLAY)
    {
      fail("no display");
      continue;
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(candidate.Display, &major, &minor))
    {
      fail("eglInitialize failed (" + EGLErrorText(eglGetError()) + ")");
      continue;
    }
    const char* extensions = eglQueryString(candidate.Display, EGL_EXTENSIONS);
    if (!HasExtension(extensions, "EGL_KHR_surfaceless_context"))
    {
      fail("no EGL_KHR_surfaceless_context");
      eglTerminate(candidate.Display);
      continue;
    }
    const bool es = api == ContextApi::ES3;
    if (!eglBindAPI(es ? EGL_OPENGL_ES_API : EGL_OPENGL_API))
    {
      fail(std::string("cannot bind ") + (es ? "OpenGL ES" : "OpenGL"));
      eglTerminate(candidate.Display);
      continue;
    }
    // No surface type required: the context draws only into framebuffer objects.
    const EGLint configAttributes[] = { EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, es ? EGL_OPENGL_ES3_BIT : EGL_OPENGL_BIT,
      EGL_NONE };
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (!eglChooseConfig(candidate.Display, configAttributes, &config, 1, &configs) || configs < 1)
    {
      fail(std::string("no ") + (es ? "OpenGL ES 3" : "OpenGL") + " config");
      eglTerminate(candidate.Display);
      continue;
    }
    std::vector<EGLint> contextAttributes = { EGL_CONTEXT_MAJOR_VERSION, 3,
      EGL_CONTEXT_MINOR_VERSION, es ? 0 : 2 };
    if (!es)
    {
      contextAttributes.insert(contextAttributes.end(),
        { EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT });
    }
    contextAttributes.push_back(EGL_NONE);
    EGLContext context =
      eglCreateContext(candidate.Display, config, EGL_NO_CONTEXT, contextAttributes.data());
    if (context == EGL_NO_CONTEXT)
    {
      fail("eglCreateContext failed (" + EGLErrorText(eglGetError()) + ")");
      eglTerminate(candidate.Display);
      continue;
    }
    if (!eglMakeCurrent(candidate.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
    {
      fail("eglMakeCurrent failed (" + EGLErrorText(eglGetError()) + ")");
      eglDestroyContext(candidate.Display, context);
      eglTerminate(candidate.Display);
      continue;
    }
    std::string why;
    std::shared_ptr<const GLApi> gl = GLApi::Load(LookUp, nullptr, why);
    if (!gl)
    {
      fail(why);
      eglMakeCurrent(candidate.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(candidate.Display, context);
      eglTerminate(candidate.Display);
      continue;
    }
    std::unique_ptr<HeadlessContext> result(new HeadlessContext);
    result->EGL.reset(new Handles);
    result->EGL->Display = candidate.Display;
    result->EGL->Context = context;
    result->GL = std::move(gl);
    result->Platform = candidate.Name;
    return result;
  }
  error = std::string("no EGL ") + (api == ContextApi::ES3 ? "OpenGL ES 3.0" : "OpenGL 3.2 core") +
    " context: " + (reasons.empty() ? "no EGL display" : reasons);
  return nullptr;
}

HeadlessContext::~HeadlessContext()
{
  if (this->EGL && this->EGL->Display != EGL_NO_DISPLAY)
  {
    eglMakeCurrent(this->EGL->Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(this->EGL->Display, this->EGL->Context);
    eglTerminate(this->EGL->Display);
  }
}

} // namespace headless
} // namespace mediso
