// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMedicalGLCapabilities.h"

#include "vtkMedicalGLUtilities.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkRenderWindow.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include "vtkMedicalProbe_fs.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <vector>

#if defined(__unix__) && !defined(__APPLE__)
#include <dlfcn.h>
#define MEDISO_HAVE_DLFCN 1
#endif

vtkStandardNewMacro(vtkMedicalGLCapabilities);

namespace
{
using namespace medical_gl;
// Size of the functional-probe volume: small, odd, not a power of two, and
// with distinct extents so that swapped axes show up as mismatches.
constexpr int ProbeNX = 9;
constexpr int ProbeNY = 7;
constexpr int ProbeNZ = 5;
constexpr int ProbeCellsX = ProbeNX - 1;
constexpr int ProbeTexelsX = (ProbeNX + 3) / 4; // stored 4 points to a texel along x
constexpr int ProbeCellsY = ProbeNY - 1;

// Deterministic int16 pattern: an off-centre ellipsoidal distance field
// (negative inside, -8699 .. 18150) plus a small aperiodic ripple. It has
// column counts 0 to 4 for each probe isovalue and no mirror symmetry, so that
// swapped or flipped axes, a normalised, unsigned or 8-bit reading of the
// texture, or a constant output all give mismatches.
std::int16_t ProbeValue(int i, int j, int k)
{
  const int di = 3 * i - 10;
  const int dj = 3 * j - 8;
  const int dk = 3 * k - 5;
  const int d2 = di * di + 2 * dj * dj + 3 * dk * dk;
  return static_cast<std::int16_t>((d2 - 180) * 50 + (i * 3 + j * 5 + k * 7) % 5 - 2);
}

// The probe volume as the mapper stores a volume (vtkOpenGLHistoPyramid):
// 4 points to a texel along x, the last texel of a row repeating the row's
// last point where the points run out.
std::vector<std::int16_t> MakeProbeVolume()
{
  const int rowLength = 4 * ProbeTexelsX;
  std::vector<std::int16_t> values(static_cast<size_t>(rowLength) * ProbeNY * ProbeNZ);
  for (int k = 0; k < ProbeNZ; ++k)
  {
    for (int j = 0; j < ProbeNY; ++j)
    {
      for (int i = 0; i < rowLength; ++i)
      {
        values[(static_cast<size_t>(k) * ProbeNY + j) * rowLength + i] =
          ProbeValue(std::min(i, ProbeNX - 1), j, k);
      }
    }
  }
  return values;
}

// CPU reference of vtkMedicalProbe_fs.glsl: active cells per (i, j) column,
// row-major with i fastest, like glReadPixels returns them (from the values
// themselves, not from the texture's layout).
std::vector<unsigned int> CPUColumnCounts(float iso)
{
  std::vector<unsigned int> counts(static_cast<size_t>(ProbeCellsX) * ProbeCellsY, 0u);
  for (int j = 0; j < ProbeCellsY; ++j)
  {
    for (int i = 0; i < ProbeCellsX; ++i)
    {
      unsigned int count = 0;
      for (int k = 0; k < ProbeNZ - 1; ++k)
      {
        float vmin = 1.0e30f;
        float vmax = -1.0e30f;
        for (int c = 0; c < 8; ++c)
        {
          const int ii = i + (c & 1);
          const int jj = j + ((c >> 1) & 1);
          const int kk = k + ((c >> 2) & 1);
          const float v = static_cast<float>(ProbeValue(ii, jj, kk));
          vmin = std::min(vmin, v);
          vmax = std::max(vmax, v);
        }
        if (vmin < iso && iso <= vmax)
        {
          ++count;
        }
      }
      counts[static_cast<size_t>(j) * ProbeCellsX + i] = count;
    }
  }
  return counts;
}

std::string GLString(GLenum name)
{
  const GLubyte* s = glGetString(name);
  return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
}

// Parse "major.minor" at the start of GL_VERSION (or after "OpenGL ES ").
bool ParseGLVersion(const std::string& version, int& major, int& minor)
{
  size_t pos = 0;
  while (pos < version.size() && !std::isdigit(static_cast<unsigned char>(version[pos])))
  {
    ++pos;
  }
  int a = 0;
  int b = 0;
  std::istringstream in(version.substr(pos));
  char dot = 0;
  if (in >> a >> dot >> b && dot == '.')
  {
    major = a;
    minor = b;
    return true;
  }
  return false;
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

// Every OpenGL object of the functional probe, released on every exit path.
struct ProbeResources
{
  explicit ProbeResources(vtkOpenGLRenderWindow* win)
    : Window(win)
  {
  }
  ~ProbeResources()
  {
    if (this->VolumeActive)
    {
      this->Volume->Deactivate();
    }
    // The program belongs to the shader cache (the quad helper got the same
    // one from it): free its GL objects, which also makes the cache forget it
    // was bound; the cache recompiles it if it is ever asked for again.
    if (this->Program)
    {
      this->Program->ReleaseGraphicsResources(this->Window);
    }
    // Rebind the program that was bound before the probe, through the cache
    // so that the cache and OpenGL agree on it.
    if (this->PreviousProgram && this->PreviousProgram != this->Program)
    {
      this->Window->GetShaderCache()->ReadyShaderProgram(this->PreviousProgram);
    }
    if (this->Quad)
    {
      this->Quad->ReleaseGraphicsResources(this->Window);
      this->Quad.reset();
    }
    this->FBO->ReleaseGraphicsResources(this->Window);
    this->Counts->ReleaseGraphicsResources(this->Window);
    this->Volume->ReleaseGraphicsResources(this->Window);
  }
  ProbeResources(const ProbeResources&) = delete;
  ProbeResources& operator=(const ProbeResources&) = delete;

  vtkOpenGLRenderWindow* Window;
  vtkNew<vtkTextureObject> Volume;
  vtkNew<vtkTextureObject> Counts;
  vtkNew<vtkOpenGLFramebufferObject> FBO;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  vtkShaderProgram* Program = nullptr;         // owned by the shader cache
  vtkShaderProgram* PreviousProgram = nullptr; // idem
  bool VolumeActive = false;
};
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
  this->QueryStrings();
  if (this->VersionString.empty())
  {
    this->SetFailure(StatusNoContext, "no current OpenGL context (glGetString(GL_VERSION) failed)");
    return false;
  }
  if (this->MajorVersion < 3 || (this->MajorVersion == 3 && this->MinorVersion < 2))
  {
    std::ostringstream reason;
    reason << "OpenGL " << this->MajorVersion << "." << this->MinorVersion << " < 3.2";
    this->SetFailure(StatusMissingFeature, reason.str());
    return false;
  }
  this->QueryLimits();

  if (!this->RunFunctionalProbe(win))
  {
    return false;
  }
  this->ProbePassed = true;
  this->Supported = true;
  this->Status = StatusSupported;
  this->Reason.clear();
  return true;
}

//------------------------------------------------------------------------------
void vtkMedicalGLCapabilities::QueryStrings()
{
  TakeGLErrors(); // start from clean error flags
  this->VendorString = GLString(GL_VENDOR);
  this->RendererString = GLString(GL_RENDERER);
  this->VersionString = GLString(GL_VERSION);
  this->ShadingLanguageVersionString = GLString(GL_SHADING_LANGUAGE_VERSION);

  // GL_MAJOR_VERSION/GL_MINOR_VERSION exist from OpenGL 3.0 on; an older
  // context flags GL_INVALID_ENUM, then parse the version string instead.
  GLint major = 0;
  GLint minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (!TakeGLErrors().empty() || major <= 0)
  {
    major = 0;
    minor = 0;
    ParseGLVersion(this->VersionString, major, minor);
  }
  this->MajorVersion = major;
  this->MinorVersion = minor;
}

//------------------------------------------------------------------------------
void vtkMedicalGLCapabilities::QueryLimits()
{
  auto getInt = [](GLenum pname) {
    GLint value = 0;
    glGetIntegerv(pname, &value);
    return TakeGLErrors().empty() ? static_cast<int>(value) : 0;
  };
  this->Max3DTextureSize = getInt(GL_MAX_3D_TEXTURE_SIZE);
  this->MaxTextureSize = getInt(GL_MAX_TEXTURE_SIZE);
  this->MaxColorAttachments = getInt(GL_MAX_COLOR_ATTACHMENTS);
  this->MaxDrawBuffers = getInt(GL_MAX_DRAW_BUFFERS);
  this->CoreProfile = (getInt(GL_CONTEXT_PROFILE_MASK) & GL_CONTEXT_CORE_PROFILE_BIT) != 0;

  // GL_POINT_SIZE_RANGE is valid in the core profile (unlike
  // GL_ALIASED_POINT_SIZE_RANGE, which is compatibility only).
  GLfloat range[2] = { 0.0f, 0.0f };
  glGetFloatv(GL_POINT_SIZE_RANGE, range);
  if (TakeGLErrors().empty())
  {
    this->PointSizeRange[0] = range[0];
    this->PointSizeRange[1] = range[1];
  }
}

//------------------------------------------------------------------------------
bool vtkMedicalGLCapabilities::RunFunctionalProbe(vtkOpenGLRenderWindow* win)
{
  vtkOpenGLState* ostate = win->GetState();
  TakeGLErrors();

  // State this pass changes, restored when the scope ends (in reverse order,
  // after the resources below are released).
  vtkOpenGLState::ScopedglActiveTexture savedActiveTexture(ostate);
  vtkOpenGLState::ScopedglViewport savedViewport(ostate);
  vtkOpenGLState::ScopedglColorMask savedColorMask(ostate);
  vtkOpenGLState::ScopedglEnableDisable savedDepthTest(ostate, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable savedBlend(ostate, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable savedScissorTest(ostate, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglEnableDisable savedStencilTest(ostate, GL_STENCIL_TEST);
  vtkOpenGLState::ScopedglEnableDisable savedCullFace(ostate, GL_CULL_FACE);
  ScopedBufferUnbind savedUnpackBuffer(GL_PIXEL_UNPACK_BUFFER, GL_PIXEL_UNPACK_BUFFER_BINDING);
  ScopedBufferUnbind savedPackBuffer(GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING);

  ProbeResources res(win);

  // 1. The volume: int16 values as a GL_RGBA16I 3D texture, 4 points to a
  //    texel along x as the mapper stores them, nearest filtering (integer
  //    textures are incomplete with linear filtering).
  std::vector<std::int16_t> values = MakeProbeVolume();
  vtkTextureObject* volume = res.Volume;
  volume->SetContext(win);
  volume->SetInternalFormat(GL_RGBA16I);
  volume->SetFormat(GL_RGBA_INTEGER);
  volume->SetDataType(GL_SHORT);
  volume->SetMinificationFilter(vtkTextureObject::Nearest);
  volume->SetMagnificationFilter(vtkTextureObject::Nearest);
  volume->SetWrapS(vtkTextureObject::ClampToEdge);
  volume->SetWrapT(vtkTextureObject::ClampToEdge);
  volume->SetWrapR(vtkTextureObject::ClampToEdge);
  const bool volumeCreated =
    volume->Create3DFromRaw(ProbeTexelsX, ProbeNY, ProbeNZ, 4, VTK_SHORT, values.data());
  std::string errors = TakeGLErrors();
  if (!volumeCreated || !errors.empty())
  {
    this->SetFailure(StatusMissingFeature,
      "cannot create a GL_RGBA16I 3D texture" + (errors.empty() ? "" : ": " + errors));
    return false;
  }
  if (volume->GetInternalFormat(VTK_SHORT, 4, false) != GL_RGBA16I ||
    volume->GetFormat(VTK_SHORT, 4, false) != GL_RGBA_INTEGER ||
    static_cast<unsigned int>(volume->GetDataType(VTK_SHORT)) != GL_SHORT)
  {
    this->SetFailure(StatusProbeFailed,
      "vtkTextureObject did not keep the GL_RGBA16I / GL_RGBA_INTEGER / GL_SHORT formats");
    return false;
  }

  // 2. The target: one GL_R32UI texel per cell column, in a framebuffer object.
  vtkTextureObject* counts = res.Counts;
  counts->SetContext(win);
  counts->SetInternalFormat(GL_R32UI);
  counts->SetFormat(GL_RED_INTEGER);
  counts->SetDataType(GL_UNSIGNED_INT);
  counts->SetMinificationFilter(vtkTextureObject::Nearest);
  counts->SetMagnificationFilter(vtkTextureObject::Nearest);
  counts->SetWrapS(vtkTextureObject::ClampToEdge);
  counts->SetWrapT(vtkTextureObject::ClampToEdge);
  const bool countsCreated = counts->Allocate2D(ProbeCellsX, ProbeCellsY, 1, VTK_UNSIGNED_INT);
  errors = TakeGLErrors();
  if (!countsCreated || !errors.empty())
  {
    this->SetFailure(StatusMissingFeature,
      "cannot create a GL_R32UI 2D texture" + (errors.empty() ? "" : ": " + errors));
    return false;
  }

  vtkOpenGLFramebufferObject* fbo = res.FBO;
  fbo->SetContext(win);
  ScopedFramebufferBindings savedBindings(fbo);
  fbo->Bind();
  fbo->AddColorAttachment(0, counts);
  fbo->ActivateDrawBuffers(1);
  fbo->ActivateReadBuffer(0);
  // GetFrameBufferStatus rather than CheckFrameBufferStatus: an incomplete
  // integer target is an answer here, not an error to print.
  const char* fboStatus = nullptr;
  if (!vtkOpenGLFramebufferObject::GetFrameBufferStatus(GL_FRAMEBUFFER, fboStatus))
  {
    this->SetFailure(StatusMissingFeature,
      std::string("integer render target incomplete (GL_R32UI colour attachment: ") +
        (fboStatus ? fboStatus : "unknown status") + ")");
    return false;
  }
  errors = TakeGLErrors();
  if (!errors.empty())
  {
    this->SetFailure(
      StatusMissingFeature, "cannot set up the GL_R32UI framebuffer object: " + errors);
    return false;
  }

  // 3. The program. Ready it through the shader cache first, so that a
  //    compile failure is caught here (VTK prints the compiler log) rather
  //    than inside vtkOpenGLQuadHelper's vertex array set-up; the helper then
  //    finds the same program in the cache.
  const std::string vs = vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader();
  res.PreviousProgram = win->GetShaderCache()->GetLastShaderBound();
  res.Program = win->GetShaderCache()->ReadyShaderProgram(vs.c_str(), vtkMedicalProbe_fs, "");
  if (!res.Program)
  {
    this->SetFailure(StatusProbeFailed, "shader failed to compile (vtkMedicalProbe_fs.glsl)");
    return false;
  }
  res.Quad = std::make_unique<vtkOpenGLQuadHelper>(win, vs.c_str(), vtkMedicalProbe_fs, "");
  vtkShaderProgram* program = res.Quad->Program;
  if (program != res.Program || win->GetShaderCache()->ReadyShaderProgram(program) != program)
  {
    this->SetFailure(StatusProbeFailed, "shader failed to compile (vtkMedicalProbe_fs.glsl)");
    return false;
  }
  // Our uvec4 output is not bound by VTK (see the shader); as the program's
  // only output it must have been given location 0.
  const GLint outputLocation =
    glGetFragDataLocation(static_cast<GLuint>(program->GetHandle()), "fragOutput0");
  if (outputLocation != 0)
  {
    std::ostringstream reason;
    reason << "the probe shader's integer output got location " << outputLocation
           << " instead of 0";
    this->SetFailure(StatusProbeFailed, reason.str());
    return false;
  }

  // 4. Render state: the whole target, no tests, nothing masked.
  ostate->vtkglViewport(0, 0, ProbeCellsX, ProbeCellsY);
  ostate->vtkglDisable(GL_DEPTH_TEST);
  ostate->vtkglDisable(GL_BLEND);
  ostate->vtkglDisable(GL_SCISSOR_TEST);
  ostate->vtkglDisable(GL_STENCIL_TEST);
  ostate->vtkglDisable(GL_CULL_FACE);
  ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);

  volume->Activate();
  res.VolumeActive = true;
  GLint allocatedFormat = 0;
  glGetTexLevelParameteriv(GL_TEXTURE_3D, 0, GL_TEXTURE_INTERNAL_FORMAT, &allocatedFormat);
  if (allocatedFormat != GL_RGBA16I)
  {
    std::ostringstream reason;
    reason << "the 3D texture was allocated as internal format 0x" << std::hex << allocatedFormat
           << ", not GL_RGBA16I";
    this->SetFailure(StatusMissingFeature, reason.str());
    return false;
  }
  if (!program->SetUniformi("probeVolume", volume->GetTextureUnit()))
  {
    this->SetFailure(StatusProbeFailed, "probe shader has no uniform probeVolume");
    return false;
  }
  const int probePoints[3] = { ProbeNX, ProbeNY, ProbeNZ };
  if (!SetUniformIVec3(program, "probePoints", probePoints))
  {
    this->SetFailure(StatusProbeFailed, "probe shader has no uniform probePoints");
    return false;
  }

  // 5. One pass per isovalue: two between data values and one exactly equal
  //    to a voxel value (-1798), which checks the min < iso <= max convention
  //    (min <= iso < max would give different counts in three columns).
  const float isovalues[3] = { -4000.5f, static_cast<float>(ProbeValue(6, 4, 3)), 3000.5f };
  const GLuint sentinel[4] = { 0xDEADBEEFu, 0u, 0u, 0u };
  std::vector<GLuint> gpu(static_cast<size_t>(ProbeCellsX) * ProbeCellsY);
  for (float iso : isovalues)
  {
    if (!program->SetUniformf("isovalue", iso))
    {
      this->SetFailure(StatusProbeFailed, "probe shader has no uniform isovalue");
      return false;
    }
    glClearBufferuiv(GL_COLOR, 0, sentinel);
    res.Quad->Render();
    std::fill(gpu.begin(), gpu.end(), 0xFFFFFFFFu);
    glReadPixels(0, 0, ProbeCellsX, ProbeCellsY, GL_RED_INTEGER, GL_UNSIGNED_INT, gpu.data());
    errors = TakeGLErrors();
    if (!errors.empty())
    {
      this->SetFailure(StatusProbeFailed,
        "rendering or reading back the integer probe pass failed: " + errors);
      return false;
    }
    const std::vector<unsigned int> cpu = CPUColumnCounts(iso);
    for (int j = 0; j < ProbeCellsY; ++j)
    {
      for (int i = 0; i < ProbeCellsX; ++i)
      {
        const size_t idx = static_cast<size_t>(j) * ProbeCellsX + i;
        if (gpu[idx] != cpu[idx])
        {
          std::ostringstream reason;
          reason << "probe count mismatch at (" << i << ", " << j << ") for isovalue " << iso
                 << ": GPU " << gpu[idx] << ", CPU " << cpu[idx];
          this->SetFailure(StatusProbeFailed, reason.str());
          return false;
        }
      }
    }
  }
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
  os << "functional probe (GL_RGBA16I 3D texture -> GL_R32UI target, " << ProbeNX << "x" << ProbeNY
     << "x" << ProbeNZ << " volume, 3 isovalues): " << (this->ProbePassed ? "passed" : "not passed")
     << "\n";
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
