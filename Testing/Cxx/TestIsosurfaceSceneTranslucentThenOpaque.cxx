// SPDX-License-Identifier: BSD-3-Clause
// The GPU core keeps nothing of a translucent frame in the opaque frame drawn
// after it: on one scene (IsosurfaceScene, as every host drives it), a frame
// of the phantom's translucent skin over its opaque bone, then a frame of the
// bone alone, must equal, pixel for pixel, the bone alone drawn by a fresh
// scene; and the translucent frame drawn again must equal the first one (the
// opaque frame leaves nothing behind either). Every footprint the renderer
// has: point sprites through the first-hit pass, quads in one pass, and the
// reduced target of an image sample distance of 2.
// The page's GPU path once showed a translucent layer over the opaque frame
// after a translucent one; that was the page's own meshes (WebViewer), and
// this test keeps the core, which every host shares, from doing the same.
//   TestIsosurfaceSceneTranslucentThenOpaque es|gl
//  - exit 0 when the pictures match;
//  - exit 125 (skip), printing "SKIP: <reason>", where no such EGL context
//    can be made;
//  - exit 1 on any difference or failure.
#include "GLApi.h"
#include "GLApiFunctions.h"
#include "HeadlessTestUtilities.h"
#include "IsosurfaceScene.h"
#include "PhantomTestScene.h"
#include "SceneView.h"

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

namespace
{
using namespace mediso;

constexpr int Width = 160;
constexpr int Height = 120;

// A colour and depth target of Width x Height, cleared and read back as a host would.
class Target
{
public:
  explicit Target(std::shared_ptr<const GLApi> gl)
    : GL(std::move(gl))
    , Framebuffer(*this->GL, Width, Height)
  {
  }

  bool IsComplete() const { return this->Framebuffer.IsComplete(); }

  // One frame of `scene` with `surfaces`: the picture, or empty with the reason in `error`.
  std::vector<unsigned char> Draw(IsosurfaceScene& scene,
    const std::vector<IsosurfaceLook>& surfaces, const IsosurfaceFrame& frame, std::string& error)
  {
    scene.SetSurfaces(surfaces);
    const GLfloat background[4] = { 0.1f, 0.12f, 0.16f, 1.0f };
    this->Framebuffer.Begin(background);
    if (!scene.Render(frame, error))
    {
      return {};
    }
    std::vector<unsigned char> rgba = this->Framebuffer.ReadRGBA();
    const std::string errors = this->GL->TakeErrors();
    if (!errors.empty())
    {
      error = "OpenGL errors: " + errors;
      return {};
    }
    return rgba;
  }

private:
  std::shared_ptr<const GLApi> GL;
  medical_test::TestFramebuffer Framebuffer;
};

// Pixels of `a` and `b` that differ at all.
int Differing(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b)
{
  int n = 0;
  for (std::size_t p = 0; p + 3 < a.size(); p += 4)
  {
    n += std::memcmp(&a[p], &b[p], 4) != 0 ? 1 : 0;
  }
  return n;
}
} // namespace

int main(int argc, char* argv[])
{
  bool es = false;
  auto context = medical_test::OpenTestContext(argc, argv, es);
  std::string error;
  std::cout << "EGL platform: " << context->GetPlatform() << "\n";
  const std::shared_ptr<const GLApi>& gl = context->GetGLApi();

  medical_test::PhantomTestScene phantom;
  if (!phantom.Make(48, Width, Height, error))
  {
    std::cerr << "FAIL: the phantom: " << error << "\n";
    return 1;
  }
  const IsosurfaceLook skin = medical_test::PhantomSkin(0.35f);
  const IsosurfaceLook bone = medical_test::PhantomBone();
  const std::vector<IsosurfaceLook> translucent = { skin, bone };
  const std::vector<IsosurfaceLook> opaque = { bone };

  int failures = 0;
  {
    Target target(gl);
    if (!target.IsComplete())
    {
      std::cerr << "FAIL: the target framebuffer cannot be made\n";
      return 1;
    }
    struct Case
    {
      const char* Name;
      bool Points;
      float SampleDistance;
    };
    for (const Case& c : { Case{ "points, first hit", true, 1.0f }, Case{ "quads", false, 1.0f },
           Case{ "sample distance 2", true, 2.0f } })
    {
      IsosurfaceFrame frame;
      SetFrameView(frame, phantom.View, phantom.Placement, Width, Height);
      frame.AllowPointFootprint = c.Points;
      frame.SampleDistance = c.SampleDistance;

      IsosurfaceScene fresh(nullptr);
      fresh.SetContext(gl);
      IsosurfaceScene reused(nullptr);
      reused.SetContext(gl);
      if (!fresh.SetVolume(phantom.Volume, error) || !reused.SetVolume(phantom.Volume, error))
      {
        std::cerr << "FAIL: the volume: " << error << "\n";
        return 1;
      }
      const std::vector<unsigned char> background = target.Draw(fresh, {}, frame, error);
      const std::vector<unsigned char> expected = target.Draw(fresh, opaque, frame, error);
      const std::vector<unsigned char> layered = target.Draw(reused, translucent, frame, error);
      const std::vector<unsigned char> after = target.Draw(reused, opaque, frame, error);
      const std::vector<unsigned char> again = target.Draw(reused, translucent, frame, error);
      if (background.empty() || expected.empty() || layered.empty() || after.empty() ||
        again.empty())
      {
        std::cerr << "FAIL: " << c.Name << ": a frame failed: " << error << "\n";
        return 1;
      }
      // The pictures must show something, and the skin must change the picture,
      // or the comparisons below prove nothing.
      const int drawn = Differing(expected, background);
      const int skinPixels = Differing(layered, expected);
      const int stale = Differing(after, expected);
      const int translucentAgain = Differing(again, layered);
      std::cout << c.Name << ": " << drawn << " pixels of bone, " << skinPixels
                << " changed by the skin; the opaque frame after the "
                   "translucent one differs from "
                   "a fresh one at "
                << stale << " pixels, the translucent frame again from the first at "
                << translucentAgain << "\n";
      if (drawn < Width * Height / 20 || skinPixels < Width * Height / 20)
      {
        std::cerr << "FAIL: " << c.Name << ": the scene draws too little to compare (" << drawn
                  << ", " << skinPixels << " pixels)\n";
        ++failures;
      }
      if (stale != 0)
      {
        std::cerr << "FAIL: " << c.Name << ": the opaque frame after a translucent one differs "
                  << "from the same frame of a fresh scene at " << stale << " pixels\n";
        ++failures;
      }
      if (translucentAgain != 0)
      {
        std::cerr << "FAIL: " << c.Name << ": the translucent frame after the opaque one differs "
                  << "from the first at " << translucentAgain << " pixels\n";
        ++failures;
      }
      fresh.Release();
      reused.Release();
    }
  }
  if (failures > 0)
  {
    return 1;
  }
  std::cout << (es ? "TestIsosurfaceSceneTranslucentThenOpaque es passed\n"
                   : "TestIsosurfaceSceneTranslucentThenOpaque gl passed\n");
  return 0;
}
