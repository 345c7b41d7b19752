// SPDX-License-Identifier: BSD-3-Clause
// IsosurfaceScene over a volume that streams in (issue 31; the web page's GPU path, docs/web.md
// "Streaming"), on an EGL context of OpenGL ES 3.0 (the WebGL2 subset) or OpenGL 3.2 core:
//   TestIsosurfaceSceneStreaming es|gl
// Two noisy blobs in a volume of odd size (a large one whose surface at 500 needs every brick, a
// small one in a corner whose surface at 1500 needs 27 of the 48), int16 and double, uploaded
// as a buffer of zeros, then filled brick by brick (BrickGrid's bricks of 16 points, the small
// blob's first, as the page asks for the bricks its isovalues need), each brick passed to
// RegionArrived() (a sub-region of the texture):
// - before any brick the full level counts nothing; at every stage it counts at most the dense
//   volume's cells, and exactly them (image included) for every isovalue whose bricks are all
//   there (those whose range holds it and their neighbours, as the page asks for them);
// - after the last brick the count and image are the dense volume's, with one whole upload (the
//   zeros) and one region upload per brick; EndStreaming() uploads nothing more;
// - level 0 is drawn from the host's samples (SetCoarseSource: the server's level 0, every 8th
//   point) with exactly their cells; levels 1 and 2 are refused while streaming;
// - a volume kept as bricks refuses to stream, with the reason.
// Exit 125 (skip) where no such context can be made.
#include "BrickGrid.h"
#include "GLApi.h"
#include "GLApiFunctions.h"
#include "HeadlessTestUtilities.h"
#include "HistoPyramidGLChecks.h" // BruteForceCount
#include "IsosurfaceScene.h"
#include "MedicalTestUtilities.h"
#include "SceneView.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using pyramid_checks::BruteForceCount;
using namespace mediso;

constexpr int Width = 160;
constexpr int Height = 120;
constexpr int BrickEdge = 16;

IsosurfaceFrame View(const int dims[3], double azimuth, double elevation)
{
  VolumePlacement placement;
  std::copy(dims, dims + 3, placement.Dimensions);
  double bounds[6];
  placement.Bounds(bounds);
  Camera camera;
  camera.Reset(bounds, static_cast<double>(Width) / Height);
  camera.Azimuth(azimuth);
  camera.Elevation(elevation);
  camera.OrthogonalizeViewUp();
  camera.ResetClippingRange(bounds);
  IsosurfaceFrame frame;
  SetFrameView(frame, camera, placement, Width, Height);
  return frame;
}

IsosurfaceLook Look(double value, float opacity)
{
  IsosurfaceLook look;
  look.Value = value;
  look.Color[0] = 0.95f;
  look.Color[1] = 0.8f;
  look.Color[2] = 0.7f;
  look.Opacity = opacity;
  return look;
}

// One frame of `scene` (cleared to black) into `target`: its RGBA pixels, or empty.
std::vector<unsigned char> Draw(medical_test::TestFramebuffer& target, IsosurfaceScene& scene,
  const IsosurfaceFrame& frame, std::string& error)
{
  const float black[4] = { 0.0f, 0.0f, 0.0f, 1.0f };
  target.Begin(black);
  if (!scene.Render(frame, error))
  {
    return {};
  }
  return target.ReadRGBA();
}

// Pixels that differ, and pixels covered in either image.
void Differ(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b, int& differ,
  int& covered)
{
  differ = covered = 0;
  for (std::size_t p = 0; p + 3 < a.size() && a.size() == b.size(); p += 4)
  {
    covered += (a[p] || a[p + 1] || a[p + 2] || b[p] || b[p + 1] || b[p + 2]) ? 1 : 0;
    differ += std::memcmp(&a[p], &b[p], 3) != 0 ? 1 : 0;
  }
}

// The bricks an isovalue needs, as the page asks for them (Web/static/stream.js): those whose
// range over their read points (apron 1) holds it, and their neighbours.
std::set<std::int64_t> Needed(
  const BrickGrid& grid, const std::vector<BrickRange>& ranges, double iso)
{
  std::set<std::int64_t> ids;
  const int* n = grid.GetBricksPerAxis();
  for (std::int64_t id = 0; id < grid.GetNumberOfBricks(); ++id)
  {
    const BrickRange& r = ranges[static_cast<std::size_t>(id)];
    if (!(r.Min < iso && iso <= r.Max))
    {
      continue;
    }
    int b[3];
    grid.BrickIndex(id, b);
    for (int z = std::max(0, b[2] - 1); z <= std::min(n[2] - 1, b[2] + 1); ++z)
      for (int y = std::max(0, b[1] - 1); y <= std::min(n[1] - 1, b[1] + 1); ++y)
        for (int x = std::max(0, b[0] - 1); x <= std::min(n[0] - 1, b[0] + 1); ++x)
        {
          ids.insert(grid.BrickId(x, y, z));
        }
  }
  return ids;
}

// The server's level 0: the points at multiples of 8 (without MakeCoarseCopy's last layer).
template <typename T>
std::vector<T> LevelZero(const std::vector<T>& v, const int n[3], int out[3])
{
  for (int a = 0; a < 3; ++a)
  {
    out[a] = (n[a] - 1) / 8 + 1;
  }
  std::vector<T> samples;
  for (int z = 0; z < out[2]; ++z)
    for (int y = 0; y < out[1]; ++y)
      for (int x = 0; x < out[0]; ++x)
      {
        samples.push_back(v[(static_cast<std::size_t>(8 * z) * n[1] + 8 * y) * n[0] + 8 * x]);
      }
  return samples;
}

// Two blobs and a little deterministic noise (the web page's streaming test's volume, smaller).
std::vector<std::int16_t> Blobs(const int n[3])
{
  std::vector<std::int16_t> values;
  std::uint32_t seed = 2463534242u;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        const double big = 1000.0 - 30.0 * std::hypot(i - 30.0, j - 26.0, k - 23.0);
        const double small = 2000.0 - 60.0 * std::hypot(i - 52.0, j - 45.0, k - 40.0);
        values.push_back(
          static_cast<std::int16_t>(std::lround(std::max({ 0.0, big, small })) + seed % 4));
      }
  return values;
}

template <typename T>
void Stream(const std::shared_ptr<const GLApi>& gl, medical_test::TestFramebuffer& target,
  const std::vector<T>& values, const int dims[3], const std::string& name)
{
  std::string error;
  VolumeDescription volume;
  volume.Type = ScalarTypeOf<T>();
  volume.Data = values.data();
  std::copy(dims, dims + 3, volume.Dims);
  volume.Stamp = 1;
  std::vector<T> buffer(values.size(), T(0));
  VolumeDescription streamed = volume;
  streamed.Data = buffer.data();

  const std::vector<IsosurfaceLook> looks = { Look(500, 0.45f), Look(1500, 1.0f) };
  IsosurfaceScene dense(nullptr), scene(nullptr);
  dense.SetContext(gl);
  scene.SetContext(gl);
  Check(dense.SetVolume(volume, error), name + ": the dense volume uploaded (" + error + ")");
  Check(scene.SetVolume(streamed, error) && !scene.IsBricked(),
    name + ": the buffer of zeros uploaded as one texture (" + error + ")");
  Check(scene.BeginStreaming(error) && scene.IsStreaming(), name + ": streaming (" + error + ")");

  // Level 0 from the host's samples.
  int coarseDims[3];
  const std::vector<T> coarse = LevelZero(values, dims, coarseDims);
  VolumeDescription source;
  source.Type = volume.Type;
  source.Data = coarse.data();
  std::copy(coarseDims, coarseDims + 3, source.Dims);
  Check(scene.SetCoarseSource(0, source, error), name + ": level 0 from the host (" + error + ")");
  const IsosurfaceFrame view = View(dims, 35, 20);
  for (const std::vector<IsosurfaceLook>& surfaces :
    { std::vector<IsosurfaceLook>{ looks[1] }, looks })
  {
    scene.SetSurfaces(surfaces);
    std::vector<double> isos;
    for (const IsosurfaceLook& s : surfaces)
    {
      isos.push_back(s.Value);
    }
    IsosurfaceFrame frame = view;
    frame.Level = 0;
    const bool drawn = !Draw(target, scene, frame, error).empty();
    const std::uint64_t expected = BruteForceCount(coarse, coarseDims, isos);
    std::printf("%s, %zu surfaces at level 0: %llu primitives (its samples' cells %llu)\n",
      name.c_str(), surfaces.size(), static_cast<unsigned long long>(scene.GetStats().Primitives),
      static_cast<unsigned long long>(expected));
    Check(drawn && scene.GetStats().Level == 0 && expected > 0 &&
        scene.GetActivePairs(0) == expected && scene.GetStats().Primitives == expected,
      name + ": level 0 drawn from the host's samples, exactly their cells (" + error + ")");
  }
  for (const int level : { 1, 2 })
  {
    error.clear();
    Check(!scene.UpdateLevel(level, error) && error.find("streaming") != std::string::npos,
      name + ": level " + std::to_string(level) + " refused while streaming (" + error + ")");
  }
  scene.SetSurfaces(looks);
  Check(scene.Update(error) && scene.GetActivePairs() == 0,
    name + ": before any brick the full level counts nothing (" + error + ")");

  const BrickGrid grid(dims, BrickEdge);
  const std::vector<BrickRange> ranges =
    ComputeBrickRanges(grid, volume.Type, values.data(), 1, SerialFor);
  std::vector<char> resident(static_cast<std::size_t>(grid.GetNumberOfBricks()), 0);
  const int size = static_cast<int>(sizeof(T));
  // The small blob's bricks first, then the rest in order (the page's order for that isovalue).
  const std::set<std::int64_t> small = Needed(grid, ranges, looks[1].Value);
  std::vector<std::int64_t> order(small.begin(), small.end());
  for (std::int64_t id = 0; id < grid.GetNumberOfBricks(); ++id)
  {
    if (!small.count(id))
    {
      order.push_back(id);
    }
  }
  std::printf("%s: %lld bricks; %g needs %zu, %g needs %zu\n", name.c_str(),
    static_cast<long long>(grid.GetNumberOfBricks()), looks[1].Value, small.size(), looks[0].Value,
    Needed(grid, ranges, looks[0].Value).size());
  Check(small.size() < order.size(), name + ": the small blob needs some bricks, not all");
  // The dense counts and images of each surface set: one alone, the other alone, both.
  std::vector<std::vector<IsosurfaceLook>> sets = { { looks[0] }, { looks[1] }, looks };
  std::vector<std::uint64_t> denseCounts;
  std::vector<std::vector<unsigned char>> denseImages;
  for (const auto& surfaces : sets)
  {
    dense.SetSurfaces(surfaces);
    denseImages.push_back(Draw(target, dense, view, error));
    denseCounts.push_back(dense.GetActivePairs());
  }
  int exactStages = 0, imageStages = 0;
  for (std::size_t stage = 0; stage < order.size(); ++stage)
  {
    const std::int64_t id = order[stage];
    int extent[6];
    grid.OwnedPoints(id, extent);
    std::vector<unsigned char> brick(grid.OwnedBytes(id, size));
    CopyBrick(grid, id, extent, values.data(), size, brick.data());
    Check(WriteBrick(grid, id, extent, size, brick.data(), buffer.data()),
      name + ": brick written into the buffer");
    const int first[3] = { extent[0], extent[2], extent[4] };
    const int last[3] = { extent[1], extent[3], extent[5] };
    Check(scene.RegionArrived(first, last, error),
      name + ": brick " + std::to_string(id) + " arrived (" + error + ")");
    resident[static_cast<std::size_t>(id)] = 1;
    // One surface set a stage, in turn; each where the small blob's last brick came.
    for (std::size_t which = 0; which < sets.size(); ++which)
    {
      if (which != stage % sets.size() && stage + 1 != small.size())
      {
        continue;
      }
      const std::vector<IsosurfaceLook>& surfaces = sets[which];
      bool ready = true;
      for (const IsosurfaceLook& s : surfaces)
      {
        for (const std::int64_t need : Needed(grid, ranges, s.Value))
        {
          ready = ready && resident[static_cast<std::size_t>(need)];
        }
      }
      scene.SetSurfaces(surfaces);
      Check(scene.Update(error), name + ": built (" + error + ")");
      const std::uint64_t count = scene.GetActivePairs(), full = denseCounts[which];
      Check(count <= full,
        name + ": brick " + std::to_string(id) + ": at most the dense cells (" +
          std::to_string(count) + " of " + std::to_string(full) + ")");
      if (!ready)
      {
        continue;
      }
      ++exactStages;
      Check(count == full,
        name + ": brick " + std::to_string(id) + ", " + std::to_string(surfaces.size()) +
          " surfaces whose bricks are all there: exactly the dense cells (" +
          std::to_string(count) + ", dense " + std::to_string(full) + ")");
      if (stage + 1 == small.size() || stage + 1 == order.size())
      {
        const std::vector<unsigned char> a = Draw(target, scene, view, error);
        int differ = 0, covered = 0;
        Differ(a, denseImages[which], differ, covered);
        ++imageStages;
        Check(!a.empty() && covered > 100 && differ == 0,
          name + ": brick " + std::to_string(id) + ": the image is the dense one (" +
            std::to_string(differ) + " of " + std::to_string(covered) + " pixels differ)");
      }
    }
  }
  std::printf("%s: bricks of %d points, %d stages with every needed brick exact, %d images "
              "compared\n",
    name.c_str(), BrickEdge, exactStages, imageStages);
  Check(exactStages > 2 && imageStages >= 2,
    name + ": the small blob's surface was complete (and exact) before the last brick");

  // Everything arrived: the dense count and image, one whole upload (the zeros) and one region
  // upload per brick; EndStreaming() uploads nothing more.
  scene.SetSurfaces(looks);
  dense.SetSurfaces(looks);
  std::vector<double> isos = { looks[0].Value, looks[1].Value };
  Check(
    scene.EndStreaming(error) && !scene.IsStreaming(), name + ": streaming ended (" + error + ")");
  const std::vector<unsigned char> a = Draw(target, scene, view, error);
  const std::vector<unsigned char> b = Draw(target, dense, view, error);
  int differ = 0, covered = 0;
  Differ(a, b, differ, covered);
  const IsosurfaceSceneStats& s = scene.GetStats();
  std::printf("%s, every brick: %llu primitives (dense %llu, brute force %llu), %llu whole "
              "uploads, %llu region uploads, %d of %d pixels differ\n",
    name.c_str(), static_cast<unsigned long long>(scene.GetActivePairs()),
    static_cast<unsigned long long>(dense.GetActivePairs()),
    static_cast<unsigned long long>(BruteForceCount(values, dims, isos)),
    static_cast<unsigned long long>(s.VolumeUploads),
    static_cast<unsigned long long>(s.RegionUploads), differ, covered);
  Check(scene.GetActivePairs() == dense.GetActivePairs() &&
      dense.GetActivePairs() == BruteForceCount(values, dims, isos),
    name + ": every brick: exactly the dense (and brute-force) count");
  Check(!a.empty() && covered > 500 && differ == 0, name + ": every brick: the dense image");
  Check(
    s.VolumeUploads == 1 && s.RegionUploads == static_cast<std::uint64_t>(grid.GetNumberOfBricks()),
    name + ": one whole upload (the zeros), one region upload per brick");
  // After the end the coarse levels are sampled from the volume again.
  IsosurfaceFrame frame = view;
  frame.Level = 1;
  Check(!Draw(target, scene, frame, error).empty() && scene.GetStats().Level == 1,
    name + ": after the end, level 1 is drawn from the volume (" + error + ")");
  dense.Release();
  scene.Release();
}
} // namespace

int main(int argc, char* argv[])
{
  bool es = false;
  auto context = medical_test::OpenTestContext(argc, argv, es);
  std::string error;
  const std::shared_ptr<const GLApi> gl = context->GetGLApi();
  medical_test::TestFramebuffer target(*gl, Width, Height);

  const int dims[3] = { 61, 53, 47 };
  const std::vector<std::int16_t> blobs = Blobs(dims);
  Stream(gl, target, blobs, dims, "int16");
  Stream(gl, target, std::vector<double>(blobs.begin(), blobs.end()), dims, "double");

  // A volume kept as bricks does not stream.
  {
    VolumeDescription volume;
    volume.Type = ScalarType::Int16;
    volume.Data = blobs.data();
    std::copy(dims, dims + 3, volume.Dims);
    IsosurfaceScene scene(nullptr);
    scene.SetContext(gl);
    scene.SetMaxTextureSize(32);
    Check(scene.SetVolume(volume, error) && scene.IsBricked(), "bricks: adopted (" + error + ")");
    error.clear();
    Check(!scene.BeginStreaming(error) && !scene.IsStreaming() &&
        error.find("does not stream") != std::string::npos,
      "a volume kept as bricks refuses to stream, with the reason (" + error + ")");
    scene.Release();
  }
  return medical_test::Finish(
    es ? "TestIsosurfaceSceneStreaming es passed" : "TestIsosurfaceSceneStreaming gl passed");
}
