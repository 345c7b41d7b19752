// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file HeadlessContext.h
 * @brief An OpenGL ES 3.0 or OpenGL 3.2 core context with no window and no X display (EGL).
 *
 * The headless host of the GPU core: mediso-render and the core's GL tests
 * make their context here. Displays are tried in order: Mesa's surfaceless
 * platform, then each EGL device (EGL_EXT_platform_device: what the NVIDIA
 * driver offers on a machine with no display server), then the default
 * display; MEDISO_EGL_PLATFORM=surfaceless|device|default picks one. The
 * context is made current with no surface (EGL_KHR_surfaceless_context):
 * drawing goes to framebuffer objects. GL functions come from
 * eglGetProcAddress, so only libEGL is linked.
 */
#ifndef MedicalIsosurfaces_HeadlessContext_h
#define MedicalIsosurfaces_HeadlessContext_h

#include <memory>
#include <string>

namespace mediso
{
class GLApi;

namespace headless
{

/// Which API the context offers.
enum class ContextApi
{
  ES3,   ///< OpenGL ES 3.0 or newer (the WebGL2 subset)
  GL32   ///< desktop OpenGL 3.2 core profile or newer
};

class HeadlessContext
{
public:
  /// A current context of `api`; null, with the reason in @a error, when none can be made.
  static std::unique_ptr<HeadlessContext> Create(ContextApi api, std::string& error);
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  /// The core's view of the context (loaded once, at Create()).
  const std::shared_ptr<const GLApi>& GetGLApi() const { return this->GL; }
  /// The EGL platform used ("surfaceless", "device 0", "default").
  const std::string& GetPlatform() const { return this->Platform; }

private:
  HeadlessContext() = default;
  struct Handles;
  std::unique_ptr<Handles> EGL;
  std::shared_ptr<const GLApi> GL;
  std::string Platform;
};

} // namespace headless
} // namespace mediso

#endif
