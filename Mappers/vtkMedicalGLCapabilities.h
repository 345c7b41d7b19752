// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkMedicalGLCapabilities
 * @brief   Can this OpenGL context run the GPU HistoPyramid isosurface mapper?
 *
 * vtkMedicalGLCapabilities is the single capability check of the
 * MedicalIsosurfaces GPU path. The HistoPyramid mapper (GPU cell-rasterisation
 * isosurfaces) needs an OpenGL 3.2 core / GLSL 1.50 context; it deliberately
 * uses no compute shaders and no shader storage buffers, but it does rely on
 * integer textures and integer render targets, which some drivers and remote
 * or software implementations get wrong. The mapper calls Probe() to choose
 * between the GPU path and the CPU fallback, and the tests call it to skip
 * with a readable reason instead of failing on an unsuitable machine.
 *
 * Probe() works in three steps:
 * -# It makes the context of a vtkOpenGLRenderWindow current (initialising
 *    the window first if it has no context yet; on X11 it first checks that
 *    the X display can be opened, because VTK aborts the process otherwise).
 * -# It loads the GPU core's view of the context (LoadCoreApi(): the
 *    functions from VTK's GLEW, the version, OpenGL 3.2 or newer being
 *    required, and the limits) and reports its strings and limits.
 * -# It runs the core's functional probe (mediso::ProbeGL(): a small int16
 *    volume as an RGBA16I 3D texture, classified into an R32UI target and
 *    compared with the CPU for three isovalues), which checks the integer
 *    textures and targets the HistoPyramid relies on.
 *
 * Probe() saves and restores every piece of OpenGL state it changes (current
 * context, framebuffer bindings and draw/read buffers, viewport, enable
 * flags, colour mask, active texture unit, pixel buffer bindings) and
 * releases every OpenGL object it creates before it returns, so it can be
 * called from inside a render.
 *
 * Setting the environment variable MEDISO_DISABLE_GPU_PATH to 1 (any value
 * except empty, 0, OFF, NO or FALSE) makes Probe() report the GPU path as
 * unsupported, status StatusDisabled, reason "disabled by MEDISO_DISABLE_GPU_PATH",
 * without touching OpenGL at all. Tests and benchmarks use it to force the
 * CPU fallback.
 *
 * Typical use:
 * @code
 * vtkNew<vtkMedicalGLCapabilities> caps;
 * if (!caps->Probe(renWin))
 * {
 *   std::cout << "CPU fallback: " << caps->GetReason() << "\n";
 * }
 * std::cout << caps->GetReport();
 * @endcode
 *
 * @warning Probe() needs an OpenGL render window (vtkOpenGLRenderWindow);
 * any other window, or none, gives Supported false, status StatusNoContext.
 */
#ifndef vtkMedicalGLCapabilities_h
#define vtkMedicalGLCapabilities_h

#include "MedicalIsosurfacesMappersModule.h" // For export macro
#include "vtkObject.h"

#include <memory> // For std::shared_ptr
#include <string> // For std::string

namespace mediso
{
class GLApi;
}
class vtkOpenGLRenderWindow;
class vtkRenderWindow;

class MEDICALISOSURFACESMAPPERS_EXPORT vtkMedicalGLCapabilities : public vtkObject
{
public:
  static vtkMedicalGLCapabilities* New();
  vtkTypeMacro(vtkMedicalGLCapabilities, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Outcome of the last Probe(). Everything but Supported selects the CPU
   * fallback; the distinction tells tests whether to skip or to fail.
   */
  enum StatusType
  {
    StatusNotProbed = 0,  ///< Probe() has not been called yet.
    StatusSupported,      ///< The GPU path can be used.
    StatusDisabled,       ///< MEDISO_DISABLE_GPU_PATH is set: GPU path switched off.
    StatusNoContext,      ///< No usable OpenGL window or context (a test skips).
    StatusMissingFeature, ///< The context lacks something the mapper needs (a test skips).
    StatusProbeFailed     ///< The functional probe failed: a driver or code bug (a test fails).
  };

  /**
   * Probe the OpenGL context of @a renWin (see the class description) and
   * return GetSupported(). All previous results are reset first.
   */
  bool Probe(vtkRenderWindow* renWin);

  /**
   * True when the last Probe() found the GPU path usable.
   */
  vtkGetMacro(Supported, bool);

  ///@{
  /**
   * Outcome of the last Probe(), as a StatusType value and as a word
   * ("not probed", "supported", "disabled", "no context", "missing feature",
   * "probe failed").
   */
  vtkGetMacro(Status, int);
  const char* GetStatusAsString() const;
  ///@}

  /**
   * Why the GPU path cannot be used, as one sentence (for example
   * "OpenGL 3.1 < 3.2" or "probe count mismatch at (2, 3) for isovalue 0.5:
   * GPU 1, CPU 2"). Empty when supported.
   */
  vtkGetMacro(Reason, std::string);

  ///@{
  /**
   * The OpenGL strings of the probed context (empty when not queried).
   */
  vtkGetMacro(VendorString, std::string);
  vtkGetMacro(RendererString, std::string);
  vtkGetMacro(VersionString, std::string);
  vtkGetMacro(ShadingLanguageVersionString, std::string);
  ///@}

  ///@{
  /**
   * Version of the probed context (GL_MAJOR_VERSION, GL_MINOR_VERSION, or
   * parsed from GL_VERSION where those queries fail); 0 when not queried.
   */
  vtkGetMacro(MajorVersion, int);
  vtkGetMacro(MinorVersion, int);
  ///@}

  /**
   * True when the probed context is a core-profile context.
   */
  vtkGetMacro(CoreProfile, bool);

  ///@{
  /**
   * Limits of the probed context; 0 when not queried.
   */
  vtkGetMacro(Max3DTextureSize, int);
  vtkGetMacro(MaxTextureSize, int);
  vtkGetMacro(MaxColorAttachments, int);
  vtkGetMacro(MaxDrawBuffers, int);
  vtkGetVector2Macro(PointSizeRange, float);
  ///@}

  /**
   * True when the functional probe ran and every count matched the CPU.
   */
  vtkGetMacro(ProbePassed, bool);

  /**
   * A multi-line "key: value" report of the last Probe(), one line per
   * queried value, for the header of a benchmark or demo report.
   */
  std::string GetReport() const;

  /**
   * True when MEDISO_DISABLE_GPU_PATH asks for the CPU fallback.
   */
  static bool IsGPUPathDisabledByEnvironment();

  /**
   * The GPU core's view (mediso::GLApi) of the context of @a win, which
   * must be current: its functions from VTK's GLEW, its version and
   * limits. Null, with the reason in @a error, on a window that is not an
   * OpenGL one or a context the core cannot use (older than OpenGL 3.2, a
   * function missing).
   */
  static std::shared_ptr<const mediso::GLApi> LoadCoreApi(
    vtkRenderWindow* win, std::string& error);

protected:
  vtkMedicalGLCapabilities();
  ~vtkMedicalGLCapabilities() override;

private:
  vtkMedicalGLCapabilities(const vtkMedicalGLCapabilities&) = delete;
  void operator=(const vtkMedicalGLCapabilities&) = delete;

  void ResetResults();
  void SetFailure(int status, const std::string& reason);

  bool Supported = false;
  int Status = StatusNotProbed;
  std::string Reason;
  std::string VendorString;
  std::string RendererString;
  std::string VersionString;
  std::string ShadingLanguageVersionString;
  int MajorVersion = 0;
  int MinorVersion = 0;
  bool CoreProfile = false;
  int Max3DTextureSize = 0;
  int MaxTextureSize = 0;
  int MaxColorAttachments = 0;
  int MaxDrawBuffers = 0;
  float PointSizeRange[2] = { 0.0f, 0.0f };
  bool ProbePassed = false;
};

#endif
