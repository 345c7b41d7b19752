// SPDX-License-Identifier: BSD-3-Clause
// IsosurfaceScene::ProgramsToBuild, the programs a frame would compile, asked before the frame,
// must be what the frame then compiles (GetProgramBuilds across it), frame after frame of a
// session like the page's before a drag (issue 30): the phantom's skin over its bone on volume
// levels 0 and 3, the skin alone and the bone alone on volume level -1, then the skin over the
// bone on level -1 at a drag's sample distance. That last frame compiles a program that a key of
// level and translucency (the page's own guess, before) took as compiled, because the skin alone
// had been drawn translucent on that level: the page's drag then began with a 0.6 s compile
// predicted at 86 ms. Asked before its level is built for the surfaces, the scene says it cannot
// know (-1). Each frame is drawn at every pixel and at one pixel in 6 (a smaller viewport: the
// point footprint's choice, part of the variant, depends on it).
//   TestIsosurfaceSceneProgramsToBuild es|gl
//  - exit 0 when every answer is what the frame compiled;
//  - exit 125 (skip), printing "SKIP: <reason>", where no such EGL context can be made;
//  - exit 1 otherwise.
#include "GLApi.h"
#include "GLApiFunctions.h"
#include "HeadlessTestUtilities.h"
#include "IsosurfaceScene.h"
#include "PhantomTestScene.h"
#include "SceneView.h"

#include <algorithm>
#include <array>
#include <iostream>
#include <set>
#include <string>
#include <vector>

namespace
{
using namespace mediso;

constexpr int Width = 160;
constexpr int Height = 120;
} // namespace

int main(int argc, char* argv[])
{
  bool es = false;
  auto context = medical_test::OpenTestContext(argc, argv, es);
  std::string error;
  std::cout << "EGL platform: " << context->GetPlatform() << "\n";
  const std::shared_ptr<const GLApi>& gl = context->GetGLApi();

  medical_test::PhantomTestScene phantom;
  if (!phantom.Make(64, Width, Height, error))
  {
    std::cerr << "FAIL: the phantom: " << error << "\n";
    return 1;
  }
  const IsosurfaceLook skin = medical_test::PhantomSkin(0.3f);
  const IsosurfaceLook bone = medical_test::PhantomBone();
  const std::vector<IsosurfaceLook> skinOverBone = { skin, bone };
  const std::vector<IsosurfaceLook> skinAlone = { skin };
  IsosurfaceLook boneAlone = bone;
  boneAlone.Value = 300.0;

  medical_test::TestFramebuffer target(*gl, Width, Height);
  if (!target.IsComplete())
  {
    std::cerr << "FAIL: the target framebuffer cannot be made\n";
    return 1;
  }
  IsosurfaceScene scene(nullptr);
  scene.SetContext(gl);
  if (!scene.SetVolume(phantom.Volume, error))
  {
    std::cerr << "FAIL: the volume: " << error << "\n";
    return 1;
  }

  struct Step
  {
    const char* Name;
    std::vector<IsosurfaceLook> Surfaces;
    int Level;
  };
  const std::vector<Step> session = { { "skin over bone, volume level 0", skinOverBone, 0 },
    { "skin over bone, the full volume", skinOverBone, 3 },
    { "skin alone, volume level -1", skinAlone, -1 },
    { "bone alone, volume level -1", { boneAlone }, -1 },
    { "skin over bone, volume level 0 again", skinOverBone, 0 },
    { "skin over bone, volume level -1 (the drag)", skinOverBone, -1 },
    { "skin over bone, volume level -1 again", skinOverBone, -1 } };

  // The page's key before (volume level, translucent), as its frames would have filled it.
  std::set<std::array<int, 2>> oldKey;
  int failures = 0;
  bool dragCompiled = false, dragKeyWarm = false;
  for (const Step& step : session)
  {
    for (const int distance : { 1, 6 })
    {
      IsosurfaceFrame frame;
      SetFrameView(frame, phantom.View, phantom.Placement, Width / distance, Height / distance);
      frame.Level = step.Level;
      scene.SetSurfaces(step.Surfaces);
      const bool translucent = std::any_of(step.Surfaces.begin(), step.Surfaces.end(),
        [](const IsosurfaceLook& s) { return s.Opacity < 1.0f; });
      std::vector<double> values;
      for (const IsosurfaceLook& s : step.Surfaces)
      {
        values.push_back(s.Value);
      }
      const bool built = scene.GetBuiltValues(step.Level) == values;
      const int unbuilt = scene.ProgramsToBuild(frame);
      if (!built && unbuilt != -1)
      {
        std::cerr << "FAIL: " << step.Name << ": before its level is built the scene says "
                  << unbuilt << " programs, not -1 (unknown)\n";
        ++failures;
      }
      if (!scene.UpdateLevel(step.Level, error))
      {
        std::cerr << "FAIL: " << step.Name << ": the build: " << error << "\n";
        return 1;
      }
      const int asked = scene.ProgramsToBuild(frame);
      const std::uint64_t before = scene.GetProgramBuilds();
      const GLfloat background[4] = { 0.1f, 0.12f, 0.16f, 1.0f };
      target.Begin(background);
      if (!scene.Render(frame, error))
      {
        std::cerr << "FAIL: " << step.Name << ": the frame: " << error << "\n";
        return 1;
      }
      const std::uint64_t compiled = scene.GetProgramBuilds() - before;
      const bool keyWarm = !oldKey.insert({ step.Level, translucent ? 1 : 0 }).second;
      std::cout << step.Name << ", one pixel in " << distance << ": asked " << asked
                << ", compiled " << compiled << " (the old key said "
                << (keyWarm ? "compiled" : "not compiled") << ")\n";
      if (asked < 0 || static_cast<std::uint64_t>(asked) != compiled)
      {
        std::cerr << "FAIL: " << step.Name << ", one pixel in " << distance
                  << ": ProgramsToBuild said " << asked << ", the frame compiled " << compiled
                  << "\n";
        ++failures;
      }
      const int again = scene.ProgramsToBuild(frame);
      if (again != 0)
      {
        std::cerr << "FAIL: " << step.Name << ", one pixel in " << distance
                  << ": after the frame the scene says " << again << " programs, not 0\n";
        ++failures;
      }
      if (std::string(step.Name) == "skin over bone, volume level -1 (the drag)" && distance == 1)
      {
        dragCompiled = compiled > 0;
        dragKeyWarm = keyWarm;
      }
    }
  }
  // The case this test is for must happen on this renderer, or it proves nothing.
  if (!dragCompiled || !dragKeyWarm)
  {
    std::cerr << "FAIL: the drag's frame on volume level -1 "
              << (dragCompiled ? "" : "compiled nothing") << (dragKeyWarm ? "" : ", and ")
              << (dragKeyWarm ? "" : "the old key did not take it as compiled")
              << ": the session no longer shows the case\n";
    ++failures;
  }
  const std::string errors = gl->TakeErrors();
  if (!errors.empty())
  {
    std::cerr << "FAIL: OpenGL errors: " << errors << "\n";
    ++failures;
  }
  scene.Release();
  if (failures > 0)
  {
    return 1;
  }
  std::cout << (es ? "TestIsosurfaceSceneProgramsToBuild es passed\n"
                   : "TestIsosurfaceSceneProgramsToBuild gl passed\n");
  return 0;
}
