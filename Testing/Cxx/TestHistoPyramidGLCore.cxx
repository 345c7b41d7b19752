// SPDX-License-Identifier: BSD-3-Clause
// The GPU core's HistoPyramid against the CPU model, node for node (see
// HistoPyramidGLChecks.h), with no VTK and no X display: on an EGL context
// of OpenGL ES 3.0 (the WebGL2 subset) or of OpenGL 3.2 core.
//   TestHistoPyramidGLCore es|gl
//  - exit 0 when everything matches;
//  - exit 125 (skip), printing "SKIP: <reason>", where no such EGL context
//    can be made;
//  - exit 1 on any mismatch.
// Also the scene's coarse volume levels (IsosurfaceScene::UpdateLevel()):
// at Block LOD levels 0, 1 and 2 and the scene's level -1 (stride 16) the
// pyramid's total equals the CPU model's count on that level's samples
// (MakeCoarseCopy / MakeStrideCopy, odd sizes: a shorter last cell on some
// axes), each level is built once per set of isovalues and again after a
// change, a change's update of a coarse level builds that level only
// (GetBuiltValues() says which values each level is built for), and a level
// outside -1..3 is refused with a reason.
#include "HeadlessTestUtilities.h"
#include "HistoPyramidGLChecks.h"

#include "BlockLOD.h"
#include "IsosurfaceScene.h"

#include <cstring>
#include <iostream>

namespace
{
using medical_test::Check;

void CheckCoarseLevels(const std::shared_ptr<const mediso::GLApi>& gl)
{
  const int dims[3] = { 45, 38, 29 };
  const std::vector<std::int16_t> hu = pyramid_checks::MakePhantom(dims, 20.0, 7u);
  mediso::IsosurfaceScene scene(nullptr);
  scene.SetContext(gl);
  mediso::VolumeDescription volume;
  volume.Type = mediso::ScalarType::Int16;
  volume.Data = hu.data();
  std::copy(dims, dims + 3, volume.Dims);
  std::string error;
  Check(scene.SetVolume(volume, error), "coarse levels: the volume did not upload: " + error);
  mediso::Volume<std::int16_t> full;
  full.Data = hu.data();
  std::copy(dims, dims + 3, full.Dims);
  for (const std::vector<double>& isovalues :
    std::vector<std::vector<double>>{ { -500.0 }, { -500.0, 300.0 } })
  {
    std::vector<mediso::IsosurfaceLook> looks(isovalues.size());
    for (std::size_t i = 0; i < isovalues.size(); ++i)
    {
      looks[i].Value = isovalues[i];
    }
    scene.SetSurfaces(looks);
    Check(scene.Update(error), "coarse levels: the full level did not build: " + error);
    const std::uint64_t fullPairs = scene.GetActivePairs();
    for (int level = mediso::IsosurfaceScene::CoarsestLevel; level < 3; ++level)
    {
      const std::uint64_t builds = scene.GetStats().CoarseBuilds;
      const bool built = scene.UpdateLevel(level, error) && scene.UpdateLevel(level, error);
      Check(built, "coarse level " + std::to_string(level) + " did not build: " + error);
      Check(scene.GetStats().CoarseBuilds == builds + 1,
        "coarse level " + std::to_string(level) + ": built once per set of isovalues");
      std::vector<std::int16_t> samples;
      const mediso::Volume<std::int16_t> coarse = level >= 0
        ? mediso::MakeCoarseCopy(full, level, samples, mediso::SerialFor)
        : mediso::MakeStrideCopy(full, 16, samples, mediso::SerialFor);
      const std::array<int, 3> expected = mediso::IsosurfaceScene::LevelDimensions(dims, level);
      Check(std::equal(coarse.Dims, coarse.Dims + 3, expected.begin()),
        "coarse level " + std::to_string(level) + ": LevelDimensions differs from Block LOD's");
      std::uint64_t cpu = 0;
      for (std::uint32_t c :
        mediso::HistoPyramid::CountCrossings(samples.data(), coarse.Dims, isovalues))
      {
        cpu += c;
      }
      std::cout << "coarse level " << level << " (" << coarse.Dims[0] << "x" << coarse.Dims[1]
                << "x" << coarse.Dims[2] << "), " << isovalues.size() << " isovalue(s): GPU "
                << scene.GetActivePairs(level) << ", CPU " << cpu << " (full " << fullPairs
                << ", estimate " << mediso::IsosurfaceScene::EstimateActivePairs(fullPairs, level)
                << ")\n";
      Check(scene.GetActivePairs(level) == cpu && cpu > 0 && cpu < fullPairs,
        "coarse level " + std::to_string(level) +
          ": the pyramid's total differs from the CPU model's count on the level's samples");
    }
  }
  // An isovalue change's first answer on a coarse level: its pyramid alone is built, and
  // GetBuiltValues() says which levels are built for which values (a host predicts a change's
  // build from it).
  {
    const std::vector<double> before = scene.GetBuiltValues(3);
    const std::uint64_t fullBuilds = scene.GetStats().PyramidBuilds;
    std::vector<mediso::IsosurfaceLook> looks(1);
    looks[0].Value = 100.0;
    scene.SetSurfaces(looks);
    Check(scene.UpdateLevel(1, error), "coarse level 1 after a change did not build: " + error);
    Check(scene.GetBuiltValues(1) == std::vector<double>{ 100.0 } &&
        scene.GetBuiltValues(3) == before && before == std::vector<double>{ -500.0, 300.0 } &&
        scene.GetStats().PyramidBuilds == fullBuilds,
      "a change's coarse level: only level 1 is built for the new value, the full level keeps "
      "the old ones");
    Check(scene.GetBuiltValues(2) == before && scene.GetBuiltValues(-1) == before &&
        scene.GetBuiltValues(-2).empty(),
      "coarse levels 2 and -1 still hold the old values, level -2 none");
    Check(scene.Update(error) && scene.GetBuiltValues(3) == std::vector<double>{ 100.0 },
      "the full level's build after it: " + error);
  }
  Check(scene.GetGPUMemoryBytes() >
      mediso::IsosurfaceScene::EstimateGPUMemoryBytes(mediso::ScalarType::Int16, dims),
    "coarse levels: their GPU memory is not counted");
  Check(!scene.UpdateLevel(4, error) && !error.empty(), "coarse levels: level 4 is not refused");
  error.clear();
  Check(!scene.UpdateLevel(-2, error) && !error.empty(), "coarse levels: level -2 is not refused");
  scene.Release();
}
} // namespace

int main(int argc, char* argv[])
{
  bool es = false;
  auto context = medical_test::OpenTestContext(argc, argv, es);
  std::cout << "EGL platform: " << context->GetPlatform() << "\n";
  CheckCoarseLevels(context->GetGLApi());
  return pyramid_checks::RunAll(context->GetGLApi(),
    es ? "TestHistoPyramidGLCore es passed" : "TestHistoPyramidGLCore gl passed");
}
