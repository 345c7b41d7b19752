// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file HeadlessTestUtilities.h
 * @brief What the GPU core's headless tests (no VTK, no X display) share:
 * the EGL context their command line names, and an off-screen framebuffer
 * they draw a scene into and read back as a host would.
 *
 * Each such test is run as `Test<Name> es|gl` (ctest adds one test per API):
 * @code
 * int main(int argc, char* argv[])
 * {
 *   bool es = false;
 *   auto context = medical_test::OpenTestContext(argc, argv, es); // or the test ends here
 * @endcode
 */
#ifndef HeadlessTestUtilities_h
#define HeadlessTestUtilities_h

#include "GLApi.h"
#include "GLApiFunctions.h"
#include "HeadlessContext.h"

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace medical_test
{
/// The EGL context of the test's one argument: "es" (OpenGL ES 3.0, the
/// WebGL2 subset) or "gl" (OpenGL 3.2 core), with `es` set to which. Where
/// there is none it ends the test (std::exit, before the test has made
/// anything to release): with 2 and the usage for any other arguments; with
/// 125 and "SKIP: <reason>" where the machine cannot make such a context, so
/// that ctest reports a skip rather than a pass.
inline std::unique_ptr<mediso::headless::HeadlessContext> OpenTestContext(
  int argc, char* argv[], bool& es)
{
  if (argc != 2 || (std::strcmp(argv[1], "es") != 0 && std::strcmp(argv[1], "gl") != 0))
  {
    std::cerr << "usage: " << argv[0] << " es|gl\n";
    std::exit(2);
  }
  es = std::strcmp(argv[1], "es") == 0;
  std::string error;
  auto context = mediso::headless::HeadlessContext::Create(
    es ? mediso::headless::ContextApi::ES3 : mediso::headless::ContextApi::GL32, error);
  if (!context)
  {
    std::cout << "SKIP: " << error << std::endl;
    std::exit(125);
  }
  return context;
}

/// A colour (RGBA8) and depth (24 bits) framebuffer of a fixed size, made of
/// renderbuffers in the context `gl` belongs to, which must outlive it.
class TestFramebuffer
{
public:
  TestFramebuffer(const mediso::GLApi& gl, int width, int height)
    : GL(gl)
    , Width(width)
    , Height(height)
  {
    const mediso::GLApi::Functions& f = gl.F();
    f.GenFramebuffers(1, &this->FBO);
    f.GenRenderbuffers(2, this->Buffers);
    f.BindRenderbuffer(GL_RENDERBUFFER, this->Buffers[0]);
    f.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    f.BindRenderbuffer(GL_RENDERBUFFER, this->Buffers[1]);
    f.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    f.BindFramebuffer(GL_FRAMEBUFFER, this->FBO);
    f.FramebufferRenderbuffer(
      GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, this->Buffers[0]);
    f.FramebufferRenderbuffer(
      GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, this->Buffers[1]);
    this->Complete = f.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  }
  ~TestFramebuffer()
  {
    this->GL.F().DeleteFramebuffers(1, &this->FBO);
    this->GL.F().DeleteRenderbuffers(2, this->Buffers);
  }
  TestFramebuffer(const TestFramebuffer&) = delete;
  TestFramebuffer& operator=(const TestFramebuffer&) = delete;

  /// Whether the driver accepted the attachments.
  bool IsComplete() const { return this->Complete; }

  /// Binds it as a host would before drawing a scene: the viewport over it,
  /// the depth test LEQUAL with depth written, the colour cleared to
  /// `background` and the depth to 1.
  void Begin(const float background[4]) const
  {
    const mediso::GLApi::Functions& f = this->GL.F();
    f.BindFramebuffer(GL_FRAMEBUFFER, this->FBO);
    f.Viewport(0, 0, this->Width, this->Height);
    f.Enable(GL_DEPTH_TEST);
    f.DepthFunc(GL_LEQUAL);
    f.DepthMask(GL_TRUE);
    const GLfloat one = 1.0f;
    f.ClearBufferfv(GL_COLOR, 0, background);
    f.ClearBufferfv(GL_DEPTH, 0, &one);
  }

  /// Its colour, RGBA, bottom row first.
  std::vector<unsigned char> ReadRGBA() const
  {
    const mediso::GLApi::Functions& f = this->GL.F();
    std::vector<unsigned char> rgba(4 * static_cast<std::size_t>(this->Width) * this->Height);
    f.BindFramebuffer(GL_FRAMEBUFFER, this->FBO);
    f.ReadBuffer(GL_COLOR_ATTACHMENT0);
    f.PixelStorei(GL_PACK_ALIGNMENT, 1);
    f.ReadPixels(0, 0, this->Width, this->Height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    return rgba;
  }

private:
  const mediso::GLApi& GL;
  int Width;
  int Height;
  GLuint FBO = 0;
  GLuint Buffers[2] = { 0, 0 };
  bool Complete = false;
};
} // namespace medical_test

#endif
