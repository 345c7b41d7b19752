// SPDX-License-Identifier: BSD-3-Clause
// IsosurfaceScene over a volume kept as bricks (issue 31), on an EGL context
// of OpenGL ES 3.0 (the WebGL2 subset) or OpenGL 3.2 core, no VTK, no X:
//   TestIsosurfaceSceneBricks es|gl
// A noisy phantom of odd size (and one whose last bricks own no cell) drawn with a forced small
// texture limit and a small GPU budget is kept as bricks and drawn on the GPU path with exactly the
// primitives of the one-texture scene and of a brute-force count, and images within the footprint
// tests' thresholds of the one-texture images (one opaque surface, two, translucent over opaque, a
// clipping plane, a parallel view, a sample distance of 2); float data with NaN values counts the
// same; isovalue changes evict least recently used bricks within the budget and still count
// exactly; active bricks over the budget fail with that reason; the limits set back to the defaults
// give one texture again; a change of one of two surfaces builds only the bricks it touches
// (each brick its own pyramid), the others keeping theirs. The brick pool
// (IsosurfaceScene::SetBrickPool(), on by default) is checked the same way on a phantom whose
// active bricks it holds (one pyramid built per isovalue change for all of them, one pass
// drawn), with slots reused across isovalue changes within a
// budget; where it cannot hold them (a limit of 32) and with the pool off, the bricks' own
// pyramids, and on a long thin volume whose bricks fill a fraction of their slots (a pool there
// would take over IsosurfaceScene::MaximumPoolMemoryRatio the GPU memory of the bricks' own
// pyramids) the bricks' own pyramids with the reason. Exit 125 (skip) where no such context can
// be made.
#include "GLApi.h"
#include "GLApiFunctions.h"
#include "HeadlessTestUtilities.h"
#include "HistoPyramidGLChecks.h" // MakePhantom, BruteForceCount
#include "IsosurfaceScene.h"
#include "MedicalTestUtilities.h"
#include "SceneView.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using pyramid_checks::BruteForceCount;
using namespace mediso;

constexpr int Width = 160;
constexpr int Height = 120;

// A framebuffer of Width x Height with depth, and the frames' view of a volume.
class Target
{
public:
  explicit Target(const GLApi& gl)
    : Framebuffer(gl, Width, Height)
  {
  }

  // One frame of `scene` (cleared to black); its RGB pixels, or empty with `error`.
  std::vector<unsigned char> Draw(
    IsosurfaceScene& scene, const IsosurfaceFrame& frame, std::string& error)
  {
    const GLfloat black[4] = { 0.0f, 0.0f, 0.0f, 1.0f };
    this->Framebuffer.Begin(black);
    if (!scene.Render(frame, error))
    {
      return {};
    }
    const std::vector<unsigned char> rgba = this->Framebuffer.ReadRGBA();
    std::vector<unsigned char> rgb;
    for (std::size_t p = 0; p < rgba.size(); p += 4)
    {
      rgb.insert(rgb.end(), rgba.begin() + p, rgba.begin() + p + 3);
    }
    return rgb;
  }

private:
  medical_test::TestFramebuffer Framebuffer;
};

IsosurfaceFrame View(const int dims[3], double azimuth, double elevation, bool parallel)
{
  VolumePlacement placement;
  std::copy(dims, dims + 3, placement.Dimensions);
  double bounds[6];
  placement.Bounds(bounds);
  Camera camera;
  camera.Parallel = parallel;
  camera.Reset(bounds, static_cast<double>(Width) / Height);
  camera.Azimuth(azimuth);
  camera.Elevation(elevation);
  camera.OrthogonalizeViewUp();
  camera.ResetClippingRange(bounds);
  IsosurfaceFrame frame;
  SetFrameView(frame, camera, placement, Width, Height);
  return frame;
}

IsosurfaceLook Look(double value, float r, float g, float b, float opacity)
{
  IsosurfaceLook look;
  look.Value = value;
  look.Color[0] = r;
  look.Color[1] = g;
  look.Color[2] = b;
  look.Opacity = opacity;
  return look;
}

// The footprint tests' agreement between two GPU images of one scene.
void CompareImages(
  const std::vector<unsigned char>& a, const std::vector<unsigned char>& b, const std::string& name)
{
  int either = 0, disagree = 0, both = 0;
  double diff = 0.0;
  for (std::size_t p = 0; p + 2 < a.size() && a.size() == b.size(); p += 3)
  {
    const bool ca = a[p] || a[p + 1] || a[p + 2];
    const bool cb = b[p] || b[p + 1] || b[p + 2];
    either += ca || cb;
    disagree += ca != cb;
    if (ca && cb)
    {
      ++both;
      for (int c = 0; c < 3; ++c)
      {
        diff += std::abs(static_cast<int>(a[p + c]) - static_cast<int>(b[p + c]));
      }
    }
  }
  const double agreement = either ? 1.0 - static_cast<double>(disagree) / either : 0.0;
  const double mean = both ? diff / (3.0 * both) : 255.0;
  std::printf("%s: %d pixels covered, agreement %.5f, mean difference %.3f\n", name.c_str(), either,
    agreement, mean);
  Check(
    a.size() == b.size() && either > 1000, name + ": both images drawn, the surface covers pixels");
  Check(agreement >= 0.998, name + ": covered pixels agree between one texture and bricks");
  Check(mean <= 1.0, name + ": colours agree between one texture and bricks");
}

struct Case
{
  std::string Name;
  std::vector<IsosurfaceLook> Looks;
  double Azimuth, Elevation;
  bool Parallel;
  std::vector<std::array<double, 4>> Clip;
  float SampleDistance;
};

// How the bricked scene is set: its texture limit and budget, the pool on or off, and whether
// the pool then holds the active bricks (else each brick is its own pyramid).
struct Bricking
{
  int Limit = 32;
  std::uint64_t Budget = 3u << 20;
  bool Pool = true;
  bool PoolHolds = false;
};

// The volume of `values` on `dims` points, as the scenes take it.
template<typename T>
VolumeDescription Describe(const std::vector<T>& values, const int dims[3])
{
  VolumeDescription volume;
  volume.Type = ScalarTypeOf<T>();
  volume.Data = values.data();
  std::copy(dims, dims + 3, volume.Dims);
  return volume;
}

template<typename T>
void RunCases(const std::shared_ptr<const GLApi>& gl, Target& target, const std::vector<T>& values,
  const int dims[3], const std::vector<Case>& cases, const std::string& prefix,
  const Bricking& how = Bricking())
{
  VolumeDescription volume = Describe(values, dims);
  volume.Stamp = 1;

  IsosurfaceScene dense(nullptr), bricked(nullptr);
  dense.SetContext(gl);
  bricked.SetContext(gl);
  bricked.SetMaxTextureSize(how.Limit);
  bricked.SetGPUMemoryBudget(how.Budget);
  bricked.SetBrickPool(how.Pool);
  std::string error;
  Check(
    dense.SetVolume(volume, error) && !dense.IsBricked(), prefix + ": one texture (" + error + ")");
  Check(bricked.SetVolume(volume, error) && bricked.IsBricked(),
    prefix + ": over a texture limit of " + std::to_string(how.Limit) + ", bricks (" + error + ")");
  for (const Case& c : cases)
  {
    const std::string name = prefix + " " + c.Name;
    IsosurfaceFrame frame = View(dims, c.Azimuth, c.Elevation, c.Parallel);
    frame.ClipPlanes = c.Clip;
    frame.SampleDistance = c.SampleDistance;
    dense.SetSurfaces(c.Looks);
    bricked.SetSurfaces(c.Looks);
    std::string denseError, brickError;
    const std::vector<unsigned char> a = target.Draw(dense, frame, denseError);
    const std::vector<unsigned char> b = target.Draw(bricked, frame, brickError);
    Check(!a.empty(), name + ": one texture drawn (" + denseError + ")");
    Check(!b.empty(), name + ": bricks drawn (" + brickError + ")");
    if (a.empty() || b.empty())
    {
      continue;
    }
    std::vector<double> isos;
    for (const auto& look : c.Looks)
    {
      isos.push_back(look.Value);
    }
    const std::uint64_t expected = BruteForceCount(values, dims, isos);
    const IsosurfaceSceneStats& s = bricked.GetStats();
    std::printf("%s: %llu primitives (brute force %llu), %llu of %llu bricks of %d active, "
                "%llu resident, %llu GPU bytes, %llu pool slots, %llu pyramids built%s%s\n",
      name.c_str(), static_cast<unsigned long long>(bricked.GetActivePairs()),
      static_cast<unsigned long long>(expected), static_cast<unsigned long long>(s.ActiveBricks),
      static_cast<unsigned long long>(s.Bricks), s.BrickPoints,
      static_cast<unsigned long long>(s.ResidentBricks),
      static_cast<unsigned long long>(bricked.GetGPUMemoryBytes()),
      static_cast<unsigned long long>(s.PoolSlots),
      static_cast<unsigned long long>(s.BrickPyramidBuilds),
      bricked.GetBrickPoolReason().empty() ? "" : ": ", bricked.GetBrickPoolReason().c_str());
    if (how.Pool && how.PoolHolds)
    {
      Check(s.PoolSlots >= s.ActiveBricks && s.BrickPyramidBuilds == 1,
        name + ": the pool holds the active bricks, one pyramid built over them");
    }
    else
    {
      Check(s.PoolSlots == 0 && s.BrickPyramidBuilds == s.ActiveBricks,
        name + ": each active brick its own pyramid");
    }
    Check(dense.GetActivePairs() == expected, name + ": one texture counts the brute-force cells");
    Check(bricked.GetActivePairs() == expected, name + ": bricks count exactly the same cells");
    Check(c.Clip.empty() ? s.Primitives == expected : s.Primitives <= expected,
      name + ": the frame drew them");
    Check(s.Bricks > 8 && s.ActiveBricks > 1 && s.ActiveBricks <= s.Bricks,
      name + ": several bricks, several active");
    Check(
      bricked.GetGPUMemoryBytes() <= bricked.GetGPUMemoryBudget(), name + ": within the budget");
    Check(s.FirstHit == dense.GetStats().FirstHit,
      name + ": the bricks take the first-hit pass where one texture does (one, shared)");
    CompareImages(a, b, name);
  }
  dense.Release();
  bricked.Release();
}

// One of two surfaces changed, with each brick its own pyramid (the pool off): a brick that the
// same of the old and the new isovalues cross keeps its pyramid (the unchanged skin's alone), the
// others are built; the counts stay the brute force's and the images the one texture's at every
// change (bone changed, skin changed, bone changed back).
void CheckKeptPyramids(const std::shared_ptr<const GLApi>& gl, Target& target,
  const std::vector<std::int16_t>& values, const int dims[3])
{
  VolumeDescription volume = Describe(values, dims);
  volume.Stamp = 1;
  IsosurfaceScene dense(nullptr), bricked(nullptr);
  dense.SetContext(gl);
  bricked.SetContext(gl);
  bricked.SetMaxTextureSize(32);
  bricked.SetGPUMemoryBudget(3u << 20);
  bricked.SetBrickPool(false);
  std::string error;
  Check(dense.SetVolume(volume, error) && bricked.SetVolume(volume, error) && bricked.IsBricked(),
    "kept pyramids: the volume as bricks (" + error + ")");
  const IsosurfaceFrame frame = View(dims, 40, 25, false);
  const double bones[] = { 400, 600, 600, 400 };
  const double skins[] = { -500, -500, -450, -450 };
  for (int step = 0; step < 4; ++step)
  {
    const std::vector<IsosurfaceLook> looks = { Look(skins[step], 0.93f, 0.75f, 0.62f, 1.0f),
      Look(bones[step], 0.95f, 0.95f, 0.9f, 1.0f) };
    dense.SetSurfaces(looks);
    bricked.SetSurfaces(looks);
    std::string denseError, brickError;
    const std::vector<unsigned char> a = target.Draw(dense, frame, denseError);
    const std::vector<unsigned char> b = target.Draw(bricked, frame, brickError);
    const std::string name = "kept pyramids, skin " + std::to_string(int(skins[step])) +
      ", bone " + std::to_string(int(bones[step]));
    Check(!a.empty() && !b.empty(), name + ": drawn (" + denseError + brickError + ")");
    const std::uint64_t expected =
      BruteForceCount(values, dims, { skins[step], bones[step] });
    const IsosurfaceSceneStats& s = bricked.GetStats();
    std::printf("%s: %llu primitives (brute force %llu), %llu active bricks, %llu pyramids "
                "built\n",
      name.c_str(), static_cast<unsigned long long>(bricked.GetActivePairs()),
      static_cast<unsigned long long>(expected), static_cast<unsigned long long>(s.ActiveBricks),
      static_cast<unsigned long long>(s.BrickPyramidBuilds));
    Check(bricked.GetActivePairs() == expected && dense.GetActivePairs() == expected,
      name + ": the brute-force count");
    if (step == 0 || step == 2)
    {
      // The first build, and the skin changed: the skin crosses every active brick here.
      Check(s.PoolSlots == 0 && s.BrickPyramidBuilds == s.ActiveBricks,
        name + ": every active brick built");
    }
    else
    {
      Check(s.BrickPyramidBuilds > 0 && s.BrickPyramidBuilds < s.ActiveBricks,
        name + ": the bricks that only the unchanged skin crosses keep their pyramids");
    }
    if (!a.empty() && !b.empty())
    {
      CompareImages(a, b, name);
    }
  }
  dense.Release();
  bricked.Release();
}

// A ramp along x over `dims` (each value its point's x), so that an isovalue between two whole
// numbers crosses one column of bricks, all of it.
std::vector<std::int16_t> MakeRamp(const int dims[3])
{
  std::vector<std::int16_t> ramp(static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]);
  for (std::size_t i = 0; i < ramp.size(); ++i)
  {
    ramp[i] = static_cast<std::int16_t>(i % static_cast<std::size_t>(dims[0]));
  }
  return ramp;
}

// A scene kept as bricks (a texture limit of 128 and `budget`), the pool on or off.
void SetUpBricks(
  IsosurfaceScene& scene, const std::shared_ptr<const GLApi>& gl, std::uint64_t budget, bool pool)
{
  scene.SetContext(gl);
  scene.SetMaxTextureSize(128);
  scene.SetGPUMemoryBudget(budget);
  scene.SetBrickPool(pool);
}

// What a bricked scene made for `isos` alone does with `volume`.
struct Alone
{
  bool Updated = false;
  std::uint64_t PoolSlots = 0;
  std::uint64_t Bytes = 0;
  std::string Reason;
};

Alone UpdateAlone(const std::shared_ptr<const GLApi>& gl, const VolumeDescription& volume,
  const std::vector<double>& isos, std::uint64_t budget, bool pool)
{
  IsosurfaceScene scene(nullptr);
  SetUpBricks(scene, gl, budget, pool);
  std::vector<IsosurfaceLook> looks;
  for (const double iso : isos)
  {
    looks.push_back(Look(iso, 1, 1, 1, 1));
  }
  scene.SetSurfaces(looks);
  std::string error;
  Alone alone;
  alone.Updated = scene.SetVolume(volume, error) && scene.IsBricked() && scene.Update(error);
  alone.PoolSlots = scene.GetStats().PoolSlots;
  alone.Bytes = scene.GetGPUMemoryBytes();
  alone.Reason = scene.GetBrickPoolReason();
  scene.Release();
  return alone;
}

// What a run of isovalue changes showed: a pool, the bricks' own pyramids, active bricks over
// the budget, a pool given up for a smaller one.
struct PoolChanges
{
  bool Pooled = false, Own = false, Over = false, MadeSmaller = false;
};

// One scene over `values` taken through `changes` (each a list of isovalues); after each it
// draws as a scene made for those isovalues alone decides: from the pool, from the bricks' own
// pyramids with the same reason, or not at all with the same over-budget reason; its count the
// dense volume's brute-force count, its frame's primitives that count, and a pool within
// MaximumPoolMemoryRatio the GPU memory of the same bricks as their own pyramids.
PoolChanges RunPoolChanges(const std::shared_ptr<const GLApi>& gl, Target& target,
  const std::vector<std::int16_t>& values, const int dims[3], std::uint64_t budget,
  const std::vector<std::vector<double>>& changes, const std::string& prefix)
{
  VolumeDescription volume = Describe(values, dims);
  volume.Stamp = 1;
  std::string error;
  IsosurfaceScene scene(nullptr);
  SetUpBricks(scene, gl, budget, true);
  Check(scene.SetVolume(volume, error) && scene.IsBricked(), prefix + ": bricks (" + error + ")");
  PoolChanges seen;
  std::uint64_t lastSlots = 0;
  for (std::size_t i = 0; i < changes.size(); ++i)
  {
    const std::vector<double>& isos = changes[i];
    std::string name = prefix + ", change " + std::to_string(i) + " to";
    std::vector<IsosurfaceLook> looks;
    for (const double iso : isos)
    {
      char text[32];
      std::snprintf(text, sizeof(text), " %g", iso);
      name += text;
      looks.push_back(Look(iso, 1, 1, 1, 1));
    }
    const Alone fresh = UpdateAlone(gl, volume, isos, budget, true);
    scene.SetSurfaces(looks);
    error.clear();
    const bool updated = scene.Update(error);
    const IsosurfaceSceneStats& s = scene.GetStats();
    const std::string reason = scene.GetBrickPoolReason();
    std::printf("%s: %s, %llu active, %llu pool slots (alone %llu), %llu pyramids built, %llu GPU "
                "bytes%s%s\n",
      name.c_str(), updated ? "drawn" : "not drawn",
      static_cast<unsigned long long>(s.ActiveBricks), static_cast<unsigned long long>(s.PoolSlots),
      static_cast<unsigned long long>(fresh.PoolSlots),
      static_cast<unsigned long long>(s.BrickPyramidBuilds),
      static_cast<unsigned long long>(scene.GetGPUMemoryBytes()), reason.empty() ? "" : ": ",
      reason.c_str());
    Check(updated == fresh.Updated && (!updated || (s.PoolSlots > 0) == (fresh.PoolSlots > 0)) &&
        reason == fresh.Reason,
      name + ": decided as a scene made for these isovalues alone (" +
        (fresh.PoolSlots > 0 ? std::string("the pool") : "no pool: " + fresh.Reason) + ")");
    if (!updated)
    {
      seen.Over = true;
      Check(s.OverBudget && error.find("over the budget") != std::string::npos &&
          reason.find("over the budget") != std::string::npos,
        name + ": over the budget, said by the update and the pool's reason (" + error + ")");
      continue;
    }
    const std::uint64_t expected = BruteForceCount(values, dims, isos);
    Check(scene.GetActivePairs() == expected, name + ": the dense volume's count");
    std::string drawError;
    Check(!target.Draw(scene, View(dims, 20.0 * static_cast<double>(i), 10, false), drawError)
             .empty() &&
        scene.GetStats().Primitives == expected,
      name + ": drawn, its primitives the count (" + drawError + ")");
    if (s.PoolSlots > 0)
    {
      seen.Pooled = true;
      Check(reason.empty() && s.BrickPyramidBuilds == 1, name + ": one pyramid over the pool");
      const std::uint64_t own = UpdateAlone(gl, volume, isos, budget, false).Bytes;
      Check(static_cast<double>(scene.GetGPUMemoryBytes()) <=
          IsosurfaceScene::MaximumPoolMemoryRatio * static_cast<double>(own),
        name + ": the pool within the ratio of the bricks' own pyramids (" + std::to_string(own) +
          " bytes)");
      seen.MadeSmaller = seen.MadeSmaller || (lastSlots > 0 && s.PoolSlots < lastSlots);
      lastSlots = s.PoolSlots;
    }
    else
    {
      seen.Own = true;
      Check(s.BrickPyramidBuilds == s.ActiveBricks && !reason.empty(),
        name + ": each brick its own pyramid, with the reason");
      lastSlots = 0;
    }
  }
  scene.Release();
  return seen;
}

// Whether the pool draws follows the isovalues of each change, not those it was made for
// (issue 31: the pool re-checked when the crossed bricks change), in bricks of 56 points.
void CheckPoolFollowsIsovalues(const std::shared_ptr<const GLApi>& gl, Target& target)
{
  const int dims[3] = { 150, 130, 120 };
  // On the ramp, the columns of bricks x 0-55 (isovalue 30.5), 56-111 (85.5) and 112-149
  // (130.5: 38 points wide, so thin that a pool would take over MaximumPoolMemoryRatio their own
  // pyramids). The budget holds a pool of two columns: one column's pool, the thin column's
  // own pyramids, back, two columns' pool (room for 20), one column again (a pool of 20 slots
  // for 9 bricks would be over the ratio: a smaller pool), the thin column after it (9 bricks
  // that the pool's 10 slots would hold, over the ratio: their own pyramids).
  {
    const std::vector<std::int16_t> ramp = MakeRamp(dims);
    VolumeDescription volume = Describe(ramp, dims);
    const std::vector<double> one = { 30.5 }, two = { 30.5, 85.5 }, thin = { 130.5 };
    const std::uint64_t budget = UpdateAlone(gl, volume, two, 24u << 20, true).Bytes;
    const PoolChanges seen = RunPoolChanges(gl, target, ramp, dims, budget,
      { one, thin, one, two, one, thin, two, thin }, "pool follows the isovalues, ramp");
    Check(seen.Pooled && seen.Own && seen.MadeSmaller,
      "pool follows the isovalues, ramp: the pool, the bricks' own pyramids and a smaller pool "
      "for fewer bricks were all seen");
  }
  // Blobs of -2000 in one brick and -1000 in three others (-1500 crosses one brick, -500 four),
  // and spikes of 1000 every 8 points (500 crosses all 27 bricks). The budget is below what all
  // the bricks take as their own pyramids: the four bricks' pool, all of them over the budget,
  // the pool back, one brick (a smaller pool), over the budget, one brick, four.
  {
    std::vector<std::int16_t> values(static_cast<std::size_t>(dims[0]) * dims[1] * dims[2], 0);
    const int blobs[4][4] = { { 28, 28, 28, -2000 }, { 84, 28, 28, -1000 }, { 28, 84, 28, -1000 },
      { 84, 84, 84, -1000 } };
    for (int z = 0; z < dims[2]; ++z)
    {
      for (int y = 0; y < dims[1]; ++y)
      {
        for (int x = 0; x < dims[0]; ++x)
        {
          std::int16_t v = (x % 8 == 4 && y % 8 == 4 && z % 8 == 4) ? 1000 : 0;
          for (const auto& b : blobs)
          {
            const int dx = x - b[0], dy = y - b[1], dz = z - b[2];
            v = dx * dx + dy * dy + dz * dz <= 100 ? static_cast<std::int16_t>(b[3]) : v;
          }
          values[(static_cast<std::size_t>(z) * dims[1] + y) * dims[0] + x] = v;
        }
      }
    }
    VolumeDescription volume = Describe(values, dims);
    const std::vector<double> oneBrick = { -1500.5 }, fourBricks = { -500.5 }, all = { 500.5 };
    const std::uint64_t pool = UpdateAlone(gl, volume, fourBricks, 24u << 20, true).Bytes;
    const std::uint64_t own = UpdateAlone(gl, volume, all, 24u << 20, false).Bytes;
    std::printf("pool follows the isovalues, blobs: four bricks' pool %llu bytes, all bricks' own "
                "pyramids %llu\n",
      static_cast<unsigned long long>(pool), static_cast<unsigned long long>(own));
    Check(pool < own, "pool follows the isovalues, blobs: the pool of four below all bricks");
    const PoolChanges seen = RunPoolChanges(gl, target, values, dims, (pool + own) / 2,
      { fourBricks, all, fourBricks, oneBrick, all, oneBrick, fourBricks },
      "pool follows the isovalues, blobs");
    Check(seen.Pooled && seen.Over && seen.MadeSmaller,
      "pool follows the isovalues, blobs: the pool, over the budget and back, and a smaller pool "
      "for fewer bricks were all seen");
  }
}
} // namespace

int main(int argc, char* argv[])
{
  bool es = false;
  auto context = medical_test::OpenTestContext(argc, argv, es);
  std::string error;
  const std::shared_ptr<const GLApi> gl = context->GetGLApi();
  Target target(*gl);

  const int dims[3] = { 61, 53, 47 };
  const std::vector<std::int16_t> phantom = pyramid_checks::MakePhantom(dims, 40.0, 7);
  const IsosurfaceLook skin = Look(-500, 0.93f, 0.75f, 0.62f, 1.0f);
  const IsosurfaceLook bone = Look(400, 0.95f, 0.95f, 0.9f, 1.0f);
  const IsosurfaceLook glass = Look(-500, 0.93f, 0.75f, 0.62f, 0.4f);
  const std::vector<Case> cases = {
    { "bone", { bone }, 0, 0, false, {}, 1.0f },
    { "skin and bone, turned", { skin, bone }, 40, 25, false, {}, 1.0f },
    { "translucent skin over bone", { glass, bone }, -60, 10, false, {}, 1.0f },
    { "bone, clipped", { bone }, 30, 0, false, { { 1.0, 0.2, 0.0, -29.0 } }, 1.0f },
    { "skin, parallel", { skin }, 120, -20, true, {}, 1.0f },
    { "bone, sample distance 2", { bone }, 200, 30, false, {}, 2.0f },
  };
  RunCases(gl, target, phantom, dims, cases, "int16");
  // The same with the pool off: each brick its own pyramid as well.
  {
    Bricking off;
    off.Pool = false;
    RunCases(gl, target, phantom, dims, { cases[1], cases[2] }, "int16, no pool", off);
  }
  CheckKeptPyramids(gl, target, phantom, dims);
  // The pool holding every active brick: 27 bricks of 56 points (a 24 MB budget allows no
  // larger) in 64-point slots of a pool within a texture limit of 128.
  const int large[3] = { 150, 130, 120 };
  const std::vector<std::int16_t> largePhantom = pyramid_checks::MakePhantom(large, 40.0, 11);
  {
    Bricking pool;
    pool.Limit = 128;
    pool.Budget = 24u << 20;
    pool.PoolHolds = true;
    RunCases(gl, target, largePhantom, large, cases, "int16 pool", pool);
  }
  // Sizes whose last brick on an axis owns one plane of points and no cell (48 = 2 x 24).
  {
    const int edge[3] = { 49, 25, 49 };
    Bricking held; // 4 active bricks of 24: the pool's 4 slots of 32 under the limit hold them
    held.PoolHolds = true;
    RunCases(gl, target, pyramid_checks::MakePhantom(edge, 40.0, 3), edge, { cases[1] },
      "int16 49x25x49", held);
  }

  // A long thin volume (its bricks 26x26x58 points, each an eighth of a 64-point slot, as the
  // 96x96x2100 phantom's bricks of 96x96x251 points fill 256-point slots): a pool would take
  // over 6x the GPU memory of the bricks' own pyramids, so they are drawn as their own, the
  // reason says so, and the scene takes at most MaximumPoolMemoryRatio the bytes of the same
  // scene with the pool off; the counts exact, and drawn (a volume this thin covers too few
  // pixels of the test's image for the image comparison).
  {
    const int thin[3] = { 26, 26, 500 };
    const std::vector<std::int16_t> values = pyramid_checks::MakePhantom(thin, 40.0, 5);
    VolumeDescription volume = Describe(values, thin);
    std::uint64_t bytes[2] = { 0, 0 };
    std::string reasons[2];
    for (int pool = 0; pool < 2; ++pool)
    {
      IsosurfaceScene scene(nullptr);
      scene.SetContext(gl);
      scene.SetMaxTextureSize(128);
      scene.SetGPUMemoryBudget(24u << 20); // bricks of 56 points in 64-point slots
      scene.SetBrickPool(pool == 1);
      scene.SetSurfaces({ skin, bone });
      Check(scene.SetVolume(volume, error) && scene.IsBricked() && scene.Update(error) &&
          scene.GetActivePairs() == BruteForceCount(values, thin, { -500.0, 400.0 }),
        "26x26x500: bricks, the exact count (" + error + ")");
      const IsosurfaceSceneStats& s = scene.GetStats();
      Check(s.PoolSlots == 0 && s.BrickPyramidBuilds == s.ActiveBricks && s.ActiveBricks > 1 &&
          s.Bricks > 8,
        "26x26x500: several bricks, each active one its own pyramid");
      std::string drawError;
      Check(!target.Draw(scene, View(thin, 60, 20, false), drawError).empty() &&
          scene.GetStats().Primitives == scene.GetActivePairs(),
        "26x26x500: drawn (" + drawError + ")");
      bytes[pool] = scene.GetGPUMemoryBytes();
      reasons[pool] = scene.GetBrickPoolReason();
      std::printf("26x26x500, pool %s: %llu GPU bytes, %llu pool slots: %s\n", pool ? "on" : "off",
        static_cast<unsigned long long>(bytes[pool]),
        static_cast<unsigned long long>(scene.GetStats().PoolSlots), reasons[pool].c_str());
      scene.Release();
    }
    char ratio[32];
    std::snprintf(ratio, sizeof(ratio), "%gx", IsosurfaceScene::MaximumPoolMemoryRatio);
    Check(static_cast<double>(bytes[1]) <=
        IsosurfaceScene::MaximumPoolMemoryRatio * static_cast<double>(bytes[0]),
      "26x26x500: the pool on takes at most " + std::string(ratio) +
        " the GPU memory of the bricks' own pyramids");
    Check(reasons[0] == "the brick pool is off" &&
        reasons[1].find("crossed bricks' own pyramids") != std::string::npos,
      "26x26x500: the reasons say the pool is off, and over the ratio");
  }

  // Float data with NaN values: cells with a NaN corner count nothing, in bricks too.
  {
    std::vector<float> values(phantom.begin(), phantom.end());
    for (std::size_t i = 0; i < values.size(); i += 37)
    {
      values[i] = std::nanf("");
    }
    RunCases(gl, target, values, dims, { cases[1] }, "float with NaN");
    Bricking pool;
    pool.Limit = 128;
    pool.Budget = 24u << 20;
    pool.PoolHolds = true;
    std::vector<float> largeValues(largePhantom.begin(), largePhantom.end());
    for (std::size_t i = 0; i < largeValues.size(); i += 37)
    {
      largeValues[i] = std::nanf("");
    }
    RunCases(gl, target, largeValues, large, { cases[1] }, "float with NaN, pool", pool);
  }

  // Isovalue changes within a budget that holds the bricks of one change but
  // not of all: least recently used bricks go, the counts stay exact.
  {
    VolumeDescription volume = Describe(phantom, dims);
    // Bricks of 8 points (a limit of 16 texels); the bytes each isovalue's
    // bricks take, each alone; the budget then holds the largest of them.
    const std::vector<double> changes = { 1000.0, -500.0, 400.0, 1000.0, -500.0 };
    std::uint64_t largest = 0;
    for (const double iso : changes)
    {
      IsosurfaceScene alone(nullptr);
      alone.SetContext(gl);
      alone.SetMaxTextureSize(16);
      alone.SetSurfaces({ Look(iso, 1, 1, 1, 1) });
      Check(alone.SetVolume(volume, error) && alone.Update(error), "budget: alone (" + error + ")");
      largest = std::max(largest, alone.GetGPUMemoryBytes());
      alone.Release();
    }
    IsosurfaceScene scene(nullptr);
    scene.SetContext(gl);
    scene.SetMaxTextureSize(16);
    scene.SetGPUMemoryBudget(largest);
    Check(scene.SetVolume(volume, error) && scene.IsBricked(), "budget: bricks (" + error + ")");
    std::uint64_t uploads = 0;
    for (const double iso : changes)
    {
      scene.SetSurfaces({ Look(iso, 1, 1, 1, 1) });
      const bool updated = scene.Update(error);
      const IsosurfaceSceneStats& s = scene.GetStats();
      std::printf(
        "budget, iso %g: %llu active, %llu resident, %llu uploads so far, %llu GPU bytes%s\n", iso,
        static_cast<unsigned long long>(s.ActiveBricks),
        static_cast<unsigned long long>(s.ResidentBricks),
        static_cast<unsigned long long>(s.BrickUploads),
        static_cast<unsigned long long>(scene.GetGPUMemoryBytes()), updated ? "" : " (over)");
      Check(updated, "budget, iso " + std::to_string(iso) + ": fits (" + error + ")");
      Check(scene.GetActivePairs() == BruteForceCount(phantom, dims, { iso }),
        "budget, iso " + std::to_string(iso) + ": exact count");
      Check(scene.GetGPUMemoryBytes() <= scene.GetGPUMemoryBudget(),
        "budget, iso " + std::to_string(iso) + ": GPU memory within the budget");
      uploads = s.BrickUploads;
    }
    const IsosurfaceSceneStats& s = scene.GetStats();
    Check(uploads > s.ResidentBricks, "budget: bricks were evicted and uploaded again");

    // The pool within a budget that holds the slots of one change but not of all: the least
    // recently used inactive bricks give up their slots to new ones, the pool stays. A ramp
    // along x, so that each isovalue crosses one column of 3x3 bricks of 56 points.
    {
      const std::vector<std::int16_t> ramp = MakeRamp(large);
      VolumeDescription largeVolume = volume;
      largeVolume.Data = ramp.data();
      std::copy(large, large + 3, largeVolume.Dims);
      // The columns of whole bricks (x 0-55 and 56-111): the last (112-149, 38 points wide,
      // its bricks of 18 and 8 points in y and z) is thin enough beside its 64-point slots that
      // a pool for it alone would take over MaximumPoolMemoryRatio its own pyramids.
      const std::vector<double> isos = { 30.5, 85.5, 30.5, 85.5, 30.5, 85.5 };
      std::uint64_t most = 0;
      for (const double iso : isos)
      {
        IsosurfaceScene alone(nullptr);
        alone.SetContext(gl);
        alone.SetMaxTextureSize(128);
        alone.SetGPUMemoryBudget(24u << 20); // bricks of 56 points
        alone.SetSurfaces({ Look(iso, 1, 1, 1, 1) });
        Check(alone.SetVolume(largeVolume, error) && alone.Update(error) &&
            alone.GetStats().PoolSlots > 0,
          "pool budget: alone, in a pool (" + error + ")");
        most = std::max(most, alone.GetGPUMemoryBytes());
        alone.Release();
      }
      IsosurfaceScene pooled(nullptr);
      pooled.SetContext(gl);
      pooled.SetMaxTextureSize(128);
      pooled.SetGPUMemoryBudget(most);
      Check(pooled.SetVolume(largeVolume, error) && pooled.IsBricked(),
        "pool budget: bricks (" + error + ")");
      std::uint64_t slots = 0, before = 0, reused = 0;
      for (std::size_t i = 0; i < isos.size(); ++i)
      {
        pooled.SetSurfaces({ Look(isos[i], 1, 1, 1, 1) });
        const bool updated = pooled.Update(error);
        const IsosurfaceSceneStats& p = pooled.GetStats();
        std::printf("pool budget, iso %g: %llu active, %llu resident in %llu slots, %llu uploads "
                    "so far, %llu pyramids built, %llu GPU bytes\n",
          isos[i], static_cast<unsigned long long>(p.ActiveBricks),
          static_cast<unsigned long long>(p.ResidentBricks),
          static_cast<unsigned long long>(p.PoolSlots),
          static_cast<unsigned long long>(p.BrickUploads),
          static_cast<unsigned long long>(p.BrickPyramidBuilds),
          static_cast<unsigned long long>(pooled.GetGPUMemoryBytes()));
        const std::string name = "pool budget, iso " + std::to_string(isos[i]);
        Check(updated && p.PoolSlots > 0 && p.BrickPyramidBuilds == 1,
          name + ": in the pool, one pyramid (" + error + ")");
        Check(p.ActiveBricks == 9 &&
            pooled.GetActivePairs() == BruteForceCount(ramp, large, { isos[i] }),
          name + ": 9 bricks, exact count");
        Check(
          pooled.GetGPUMemoryBytes() <= pooled.GetGPUMemoryBudget(), name + ": within the budget");
        if (i >= 1)
        {
          Check(p.PoolSlots == slots, name + ": the same pool, its slots reused");
          reused += p.BrickUploads - before;
        }
        slots = p.PoolSlots;
        before = p.BrickUploads;
        // Drawn too: the frame's primitives are the count.
        IsosurfaceFrame frame = View(large, 30.0 * static_cast<double>(i), 10, false);
        std::string drawError;
        Check(!target.Draw(pooled, frame, drawError).empty() &&
            pooled.GetStats().Primitives == pooled.GetActivePairs(),
          name + ": drawn (" + drawError + ")");
      }
      Check(reused > 0 && pooled.GetStats().ResidentBricks <= pooled.GetStats().PoolSlots,
        "pool budget: evicted bricks' slots took other bricks");
      pooled.Release();
    }

    // Active bricks alone over the budget: the reason, and no volume drawn.
    scene.SetMaxTextureSize(32);
    scene.SetGPUMemoryBudget(96u << 10);
    Check(scene.SetVolume(volume, error), "small budget: the volume is adopted as bricks");
    scene.SetSurfaces({ skin, bone });
    error.clear();
    const bool updated = scene.Update(error);
    std::printf("small budget: %s\n", error.c_str());
    Check(
      !updated && scene.GetStats().OverBudget && error.find("over the budget") != std::string::npos,
      "active bricks over the budget: the update fails with that reason");
    IsosurfaceFrame frame = View(dims, 0, 0, false);
    error.clear();
    std::vector<unsigned char> none = target.Draw(scene, frame, error);
    Check(none.empty() && error.find("budget") != std::string::npos, "and so does the frame");

    // Back to the defaults: one texture, the same count.
    scene.SetGPUMemoryBudget(0);
    scene.SetMaxTextureSize(0);
    Check(scene.SetVolume(volume, error) && !scene.IsBricked() && scene.Update(error) &&
        scene.GetActivePairs() == BruteForceCount(phantom, dims, { -500.0, 400.0 }) &&
        !scene.GetStats().OverBudget && scene.GetStats().Bricks == 0,
      "default limits: one texture again, the same count (" + error + ")");
    scene.Release();
  }
  CheckPoolFollowsIsovalues(gl, target);
  return medical_test::Finish(
    es ? "TestIsosurfaceSceneBricks es passed" : "TestIsosurfaceSceneBricks gl passed");
}
