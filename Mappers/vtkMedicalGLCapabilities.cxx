// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMedicalGLCapabilities.h"

#include "vtkMedicalGLUtilities.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkRenderWindow.h"
#include "vtk_glew.h"

#include "GLApi.h"
#include "GLFunctionList.h"
#include "GLProbe.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <sstream>

#if defined(__unix__) && !defined(__APPLE__)
#include <dlfcn.h>
#define MEDISO_HAVE_DLFCN 1
#endif

vtkStandardNewMacro(vtkMedicalGLCapabilities);

namespace
{
using namespace medical_gl;

// The GPU core's functions, from the pointers VTK's GLEW loaded for the
// context (GLEW's names are macros for them; OpenGL 1.1 ones are plain functions).
void* LookUpGLEW(const char* name, void*)
{
#define MEDISO_LOOK_UP(f)                                                                          \
  if (std::strcmp(name, "gl" #f) == 0)                                                             \
  {                                                                                                \
    return reinterpret_cast<void*>(gl##f);                                                         \
  }
  MEDISO_GL_FUNCTIONS(MEDISO_LOOK_UP)
  MEDISO_GL_DESKTOP_FUNCTIONS(MEDISO_LOOK_UP)
#undef MEDISO_LOOK_UP
  return nullptr;
}

// vtkXOpenGLRenderWindow calls abort() when it cannot open the X display, so
// before initialising such a window check that the display can be opened.
// libX11 is already loaded by VTK; look it up at run time so this module does
// not have to link X11 itself.
bool XDisplayReachable(std::string& why)
{
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display)
  {
    why = "no X display: DISPLAY is not set";
    return false;
  }
#ifdef MEDISO_HAVE_DLFCN
  using OpenFn = void* (*)(const char*);
  using CloseFn = int (*)(void*);
  void* lib = dlopen("libX11.so.6", RTLD_LAZY | RTLD_LOCAL);
  if (!lib)
  {
    return true; // cannot check; let VTK try
  }
  auto openDisplay = reinterpret_cast<OpenFn>(dlsym(lib, "XOpenDisplay"));
  auto closeDisplay = reinterpret_cast<CloseFn>(dlsym(lib, "XCloseDisplay"));
  bool ok = true;
  if (openDisplay && closeDisplay)
  {
    void* dpy = openDisplay(nullptr);
    if (dpy)
    {
      closeDisplay(dpy);
    }
    else
    {
      why = std::string("no X display: cannot open DISPLAY=") + display;
      ok = false;
    }
  }
  dlclose(lib);
  return ok;
#else
  return true;
#endif
}

} // anonymous namespace

//------------------------------------------------------------------------------
vtkMedicalGLCapabilities::vtkMedicalGLCapabilities() = default;

//------------------------------------------------------------------------------
vtkMedicalGLCapabilities::~vtkMedicalGLCapabilities() = default;

//------------------------------------------------------------------------------
bool vtkMedicalGLCapabilities::IsGPUPathDisabledByEnvironment()
{
  const char* value = std::getenv("MEDISO_DISABLE_GPU_PATH");
  if (!value || !*value)
  {
    return false;
  }
  std::string v(value);
  std::transform(v.begin(), v.end(), v.begin(),
    [](unsigned char ch) { return static_cast<char>(std::toupper(ch)); });
  return !(v == "0" || v == "OFF" || v == "NO" || v == "FALSE");
}

//------------------------------------------------------------------------------
void vtkMedicalGLCapabilities::ResetResults()
{
  this->Supported = false;
  this->Status = StatusNotProbed;
  this->Reason.clear();
  this->VendorString.clear();
  this->RendererString.clear();
  this->VersionString.clear();
  this->ShadingLanguageVersionString.clear();
  this->MajorVersion = 0;
  this->MinorVersion = 0;
  this->CoreProfile = false;
  this->Max3DTextureSize = 0;
  this->MaxTextureSize = 0;
  this->MaxColorAttachments = 0;
  this->MaxDrawBuffers = 0;
  this->PointSizeRange[0] = 0.0f;
  this->PointSizeRange[1] = 0.0f;
  this->ProbePassed = false;
}

//------------------------------------------------------------------------------
void vtkMedicalGLCapabilities::SetFailure(int status, const std::string& reason)
{
  this->Supported = false;
  this->Status = status;
  this->Reason = reason;
}

//------------------------------------------------------------------------------
std::shared_ptr<const mediso::GLApi> vtkMedicalGLCapabilities::LoadCoreApi(
  vtkRenderWindow* win, std::string& error)
{
  if (!vtkOpenGLRenderWindow::SafeDownCast(win))
  {
    error = "no OpenGL render window";
    return nullptr;
  }
  return mediso::GLApi::Load(LookUpGLEW, nullptr, error);
}

//------------------------------------------------------------------------------
bool vtkMedicalGLCapabilities::Probe(vtkRenderWindow* renWin)
{
  this->ResetResults();
  this->Modified();

  if (vtkMedicalGLCapabilities::IsGPUPathDisabledByEnvironment())
  {
    this->SetFailure(StatusDisabled, "disabled by MEDISO_DISABLE_GPU_PATH");
    return false;
  }
  if (!renWin)
  {
    this->SetFailure(StatusNoContext, "no render window given");
    return false;
  }
  auto* win = vtkOpenGLRenderWindow::SafeDownCast(renWin);
  if (!win)
  {
    this->SetFailure(StatusNoContext,
      std::string("render window is a ") + renWin->GetClassName() +
        ", not a vtkOpenGLRenderWindow (is the VTK::RenderingOpenGL2 module initialised?)");
    return false;
  }

  // Create the context if the window has none yet.
  if (win->GetContextCreationTime() == 0)
  {
    std::string why;
    if (win->IsA("vtkXOpenGLRenderWindow") && !XDisplayReachable(why))
    {
      this->SetFailure(StatusNoContext, why);
      return false;
    }
    win->Initialize();
    if (win->GetContextCreationTime() == 0)
    {
      this->SetFailure(StatusNoContext, "the render window could not create an OpenGL context");
      return false;
    }
  }

  ScopedContext context(win);
  const GLubyte* version = glGetString(GL_VERSION);
  if (!version)
  {
    this->SetFailure(StatusNoContext, "no current OpenGL context (glGetString(GL_VERSION) failed)");
    return false;
  }
  this->VersionString = reinterpret_cast<const char*>(version);
  std::string error;
  const std::shared_ptr<const mediso::GLApi> gl = LoadCoreApi(win, error);
  if (!gl)
  {
    this->SetFailure(StatusMissingFeature, error);
    return false;
  }
  this->VendorString = gl->GetVendor();
  this->RendererString = gl->GetRenderer();
  this->ShadingLanguageVersionString = gl->GetShadingLanguageVersion();
  this->MajorVersion = gl->GetMajorVersion();
  this->MinorVersion = gl->GetMinorVersion();
  this->CoreProfile = gl->IsCoreProfile();
  this->Max3DTextureSize = gl->GetMax3DTextureSize();
  this->MaxTextureSize = gl->GetMaxTextureSize();
  this->MaxColorAttachments = gl->GetMaxColorAttachments();
  this->MaxDrawBuffers = gl->GetMaxDrawBuffers();
  this->PointSizeRange[0] = 1.0f;
  this->PointSizeRange[1] = gl->GetMaxPointSize();

  switch (mediso::ProbeGL(*gl, error))
  {
    case mediso::ProbeResult::Passed:
      break;
    case mediso::ProbeResult::MissingFeature:
      this->SetFailure(StatusMissingFeature, error);
      return false;
    case mediso::ProbeResult::Failed:
      this->SetFailure(StatusProbeFailed, error);
      return false;
  }
  this->ProbePassed = true;
  this->Supported = true;
  this->Status = StatusSupported;
  this->Reason.clear();
  return true;
}

//------------------------------------------------------------------------------
const char* vtkMedicalGLCapabilities::GetStatusAsString() const
{
  switch (this->Status)
  {
    case StatusSupported:
      return "supported";
    case StatusDisabled:
      return "disabled";
    case StatusNoContext:
      return "no context";
    case StatusMissingFeature:
      return "missing feature";
    case StatusProbeFailed:
      return "probe failed";
    case StatusNotProbed:
    default:
      return "not probed";
  }
}

//------------------------------------------------------------------------------
std::string vtkMedicalGLCapabilities::GetReport() const
{
  std::ostringstream os;
  os << "GPU HistoPyramid path: " << (this->Supported ? "supported" : "not supported") << "\n";
  os << "status: " << this->GetStatusAsString() << "\n";
  os << "reason: " << (this->Reason.empty() ? "-" : this->Reason) << "\n";
  if (this->VersionString.empty())
  {
    return os.str(); // not probed, disabled, or no OpenGL context reached
  }
  os << "GL_VENDOR: " << this->VendorString << "\n";
  os << "GL_RENDERER: " << this->RendererString << "\n";
  os << "GL_VERSION: " << this->VersionString << "\n";
  os << "GL_SHADING_LANGUAGE_VERSION: " << this->ShadingLanguageVersionString << "\n";
  os << "OpenGL context: " << this->MajorVersion << "." << this->MinorVersion;
  if (this->Max3DTextureSize == 0)
  {
    return os.str() + "\n"; // limits are only queried from OpenGL 3.2 on
  }
  os << (this->CoreProfile ? " core" : " compatibility") << " profile\n";
  os << "GL_MAX_3D_TEXTURE_SIZE: " << this->Max3DTextureSize << "\n";
  os << "GL_MAX_TEXTURE_SIZE: " << this->MaxTextureSize << "\n";
  os << "GL_MAX_COLOR_ATTACHMENTS: " << this->MaxColorAttachments << "\n";
  os << "GL_MAX_DRAW_BUFFERS: " << this->MaxDrawBuffers << "\n";
  os << "GL_POINT_SIZE_RANGE: " << this->PointSizeRange[0] << " " << this->PointSizeRange[1]
     << "\n";
  os << "functional probe (GL_RGBA16I 3D texture -> GL_R32UI target, 9x7x5 volume, 3 "
        "isovalues): "
     << (this->ProbePassed ? "passed" : "not passed") << "\n";
  return os.str();
}

//------------------------------------------------------------------------------
void vtkMedicalGLCapabilities::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Supported: " << (this->Supported ? "true" : "false") << "\n";
  os << indent << "Status: " << this->GetStatusAsString() << "\n";
  os << indent << "Reason: " << this->Reason << "\n";
  os << indent << "VendorString: " << this->VendorString << "\n";
  os << indent << "RendererString: " << this->RendererString << "\n";
  os << indent << "VersionString: " << this->VersionString << "\n";
  os << indent << "ShadingLanguageVersionString: " << this->ShadingLanguageVersionString << "\n";
  os << indent << "MajorVersion: " << this->MajorVersion << "\n";
  os << indent << "MinorVersion: " << this->MinorVersion << "\n";
  os << indent << "CoreProfile: " << (this->CoreProfile ? "true" : "false") << "\n";
  os << indent << "Max3DTextureSize: " << this->Max3DTextureSize << "\n";
  os << indent << "MaxTextureSize: " << this->MaxTextureSize << "\n";
  os << indent << "MaxColorAttachments: " << this->MaxColorAttachments << "\n";
  os << indent << "MaxDrawBuffers: " << this->MaxDrawBuffers << "\n";
  os << indent << "PointSizeRange: " << this->PointSizeRange[0] << " " << this->PointSizeRange[1]
     << "\n";
  os << indent << "ProbePassed: " << (this->ProbePassed ? "true" : "false") << "\n";
}
