// SPDX-License-Identifier: BSD-3-Clause
#include "IsosurfaceScene.h"

#include "BlockLOD.h" // MakeCoarseCopy, LevelStride
#include "HistoPyramidGL.h"
#include "IsosurfaceRendererGL.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

namespace mediso
{
namespace
{
using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d)
{
  return std::chrono::duration<double>(d).count();
}

// Whether two descriptions give the same volume texture.
bool SameVolume(const VolumeDescription& a, const VolumeDescription& b)
{
  return a.Type == b.Type && a.Data == b.Data && a.Stamp == b.Stamp &&
    std::equal(a.Dims, a.Dims + 3, b.Dims);
}

// The full level (the volume itself) and the coarse ones below it, as Block LOD numbers them.
constexpr int FullLevel = NumberOfLevels - 1;
} // namespace

//------------------------------------------------------------------------------
struct IsosurfaceScene::Internals
{
  GLParallelFor Parallel;
  std::shared_ptr<const GLApi> GL;
  std::unique_ptr<HistoPyramidGL> Pyramid;
  std::unique_ptr<IsosurfaceRendererGL> Renderer;

  // What the uploaded volume and the built pyramid were made from.
  bool HasVolume = false;
  VolumeDescription Volume;
  std::vector<double> BuiltValues;

  // The coarse levels (index = level, 0 to 2): made on a level's first frame, forgotten
  // with the volume.
  struct CoarseLevel
  {
    std::unique_ptr<HistoPyramidGL> Pyramid;
    std::vector<double> BuiltValues;
  };
  std::array<CoarseLevel, FullLevel> Coarse;

  std::vector<IsosurfaceLook> Surfaces;
  IsosurfaceSceneStats Stats;

  void ReleaseCoarse()
  {
    for (CoarseLevel& c : this->Coarse)
    {
      if (c.Pyramid)
      {
        c.Pyramid->Release();
      }
      c.Pyramid.reset();
      c.BuiltValues.clear();
    }
  }
  std::vector<double> Values() const
  {
    std::vector<double> values;
    for (const IsosurfaceLook& s : this->Surfaces)
    {
      values.push_back(s.Value);
    }
    return values;
  }
};

IsosurfaceScene::IsosurfaceScene(GLParallelFor parallel)
  : Impl(new Internals)
{
  this->Impl->Parallel = std::move(parallel);
}

IsosurfaceScene::~IsosurfaceScene() = default;

void IsosurfaceScene::SetContext(std::shared_ptr<const GLApi> gl)
{
  Internals& impl = *this->Impl;
  impl.GL = std::move(gl);
  impl.Pyramid.reset(impl.GL ? new HistoPyramidGL(impl.GL) : nullptr);
  impl.Renderer.reset(impl.GL ? new IsosurfaceRendererGL(impl.GL) : nullptr);
  impl.HasVolume = false;
  impl.BuiltValues.clear();
  for (Internals::CoarseLevel& c : impl.Coarse)
  {
    c.Pyramid.reset();
    c.BuiltValues.clear();
  }
}

bool IsosurfaceScene::HasContext() const
{
  return this->Impl->GL != nullptr;
}

void IsosurfaceScene::Release()
{
  Internals& impl = *this->Impl;
  if (impl.Pyramid)
  {
    impl.Pyramid->Release();
  }
  if (impl.Renderer)
  {
    impl.Renderer->Release();
  }
  impl.ReleaseCoarse();
  impl.Pyramid.reset();
  impl.Renderer.reset();
  impl.GL.reset();
  impl.HasVolume = false;
  impl.BuiltValues.clear();
}

//------------------------------------------------------------------------------
bool IsosurfaceScene::SetVolume(const VolumeDescription& volume, std::string& error)
{
  Internals& impl = *this->Impl;
  if (!impl.Pyramid)
  {
    error = "the scene has no OpenGL context";
    return false;
  }
  // The one upload decision: the values, their type or the size changed.
  if (impl.HasVolume && SameVolume(volume, impl.Volume))
  {
    return true;
  }
  impl.HasVolume = false;
  impl.BuiltValues.clear();
  impl.ReleaseCoarse();
  const auto start = Clock::now();
  if (!impl.Pyramid->UploadVolume(volume.Type, volume.Data, volume.Dims, impl.Parallel, error))
  {
    return false;
  }
  impl.Stats.UploadSeconds = Seconds(Clock::now() - start);
  ++impl.Stats.VolumeUploads;
  impl.HasVolume = true;
  impl.Volume = volume;
  return true;
}

bool IsosurfaceScene::HasVolume() const
{
  return this->Impl->HasVolume;
}

//------------------------------------------------------------------------------
SurfaceSelection IsosurfaceScene::Normalize(const std::vector<IsosurfaceLook>& looks)
{
  SurfaceSelection out;
  std::vector<std::pair<double, int>> values; // value, index in `looks`
  for (std::size_t i = 0; i < looks.size(); ++i)
  {
    if (std::isnan(looks[i].Value))
    {
      ++out.NotANumber;
    }
    else
    {
      values.emplace_back(looks[i].Value, static_cast<int>(i));
    }
  }
  if (out.NotANumber > 0)
  {
    std::ostringstream note;
    note << out.NotANumber << " of the " << looks.size() << " isovalues "
         << (out.NotANumber == 1 ? "is" : "are")
         << " not a number (NaN): an isosurface needs a numeric value; "
         << (values.empty() ? "nothing is drawn." : "the others are drawn.");
    out.Notes.push_back(note.str());
  }
  std::stable_sort(values.begin(), values.end(),
    [](const std::pair<double, int>& a, const std::pair<double, int>& b)
    { return a.first < b.first; });
  for (std::size_t i = 1; i < values.size(); ++i)
  {
    if (values[i].first == values[i - 1].first &&
      (out.Repeated.empty() || out.Repeated.back() != values[i].first))
    {
      out.Repeated.push_back(values[i].first);
    }
  }
  values.erase(std::unique(values.begin(), values.end(),
                 [](const std::pair<double, int>& a, const std::pair<double, int>& b)
                 { return a.first == b.first; }),
    values.end());
  out.Distinct = values.size();
  if (values.size() > static_cast<std::size_t>(MaximumIsovalues))
  {
    std::ostringstream note;
    note << values.size() << " isovalues requested; only the lowest " << MaximumIsovalues
         << " are drawn.";
    out.Notes.push_back(note.str());
    values.resize(MaximumIsovalues);
  }
  for (const auto& v : values)
  {
    out.Surfaces.push_back(looks[static_cast<std::size_t>(v.second)]);
    out.Sources.push_back(v.second);
  }
  return out;
}

SurfaceSelection IsosurfaceScene::SetSurfaces(const std::vector<IsosurfaceLook>& looks)
{
  SurfaceSelection selection = Normalize(looks);
  this->Impl->Surfaces = selection.Surfaces;
  return selection;
}

const std::vector<IsosurfaceLook>& IsosurfaceScene::GetSurfaces() const
{
  return this->Impl->Surfaces;
}

//------------------------------------------------------------------------------
bool IsosurfaceScene::Update(std::string& error)
{
  Internals& impl = *this->Impl;
  std::vector<double> values;
  for (const IsosurfaceLook& s : impl.Surfaces)
  {
    values.push_back(s.Value);
  }
  // The one build decision: the isovalues changed, or the volume did (an upload forgets them).
  if (values.empty() || (impl.HasVolume && values == impl.BuiltValues))
  {
    return true;
  }
  if (!impl.HasVolume)
  {
    error = "Build needs a volume uploaded first"; // HistoPyramidGL's words
    return false;
  }
  impl.BuiltValues.clear();
  const auto start = Clock::now();
  if (!impl.Pyramid->Build(values, error))
  {
    return false;
  }
  // Build() ends by reading the total back: the passes are done.
  impl.Stats.BuildSeconds = Seconds(Clock::now() - start);
  impl.Stats.BuildTilesDrawn = impl.Pyramid->GetLastTilesDrawn();
  impl.Stats.BuildTiles = impl.Pyramid->GetNumberOfTiles();
  ++impl.Stats.PyramidBuilds;
  impl.BuiltValues = std::move(values);
  return true;
}

bool IsosurfaceScene::UpdateLevel(int level, std::string& error)
{
  Internals& impl = *this->Impl;
  if (level == FullLevel)
  {
    return this->Update(error);
  }
  if (level < 0 || level > FullLevel)
  {
    error = "no volume level " + std::to_string(level) + " (levels are 0 to 3)";
    return false;
  }
  std::vector<double> values = impl.Values();
  Internals::CoarseLevel& coarse = impl.Coarse[static_cast<std::size_t>(level)];
  if (values.empty() || (impl.HasVolume && coarse.Pyramid && values == coarse.BuiltValues))
  {
    return true;
  }
  if (!impl.HasVolume)
  {
    error = "Build needs a volume uploaded first";
    return false;
  }
  coarse.BuiltValues.clear();
  if (!coarse.Pyramid || !coarse.Pyramid->HasVolume())
  {
    // The level's samples, as vtkBlockLODContour's level reads them: a copy the texture
    // takes, not kept (the host's values are the source of every level).
    coarse.Pyramid.reset(new HistoPyramidGL(impl.GL));
    bool uploaded = false;
    VisitScalarType(impl.Volume.Type,
      [&](auto zero)
      {
        using T = decltype(zero);
        Volume<T> full;
        full.Data = static_cast<const T*>(impl.Volume.Data);
        std::copy(impl.Volume.Dims, impl.Volume.Dims + 3, full.Dims);
        std::vector<T> samples;
        const Volume<T> sampled =
          MakeCoarseCopy(full, level, samples, SerialIfEmpty(impl.Parallel));
        uploaded = coarse.Pyramid->UploadVolume(
          impl.Volume.Type, samples.data(), sampled.Dims, impl.Parallel, error);
      });
    if (!uploaded)
    {
      coarse.Pyramid.reset();
      return false;
    }
  }
  if (!coarse.Pyramid->Build(values, error))
  {
    return false;
  }
  ++impl.Stats.CoarseBuilds;
  coarse.BuiltValues = std::move(values);
  return true;
}

bool IsosurfaceScene::Render(const IsosurfaceFrame& frame, std::string& error)
{
  Internals& impl = *this->Impl;
  IsosurfaceSceneStats& stats = impl.Stats;
  stats.Primitives = 0;
  stats.PointFootprint = false;
  stats.FirstHit = false;
  stats.SampleDistance = 1.0f;
  stats.Level = FullLevel;
  if (!this->UpdateLevel(frame.Level, error))
  {
    return false;
  }
  if (impl.Surfaces.empty())
  {
    return true; // nothing to draw
  }
  IsosurfaceFrame drawn = frame;
  drawn.Surfaces = impl.Surfaces;
  const HistoPyramidGL* pyramid = impl.Pyramid.get();
  if (frame.Level != FullLevel)
  {
    // Coarse point c stands for the volume's point stride * c: the index space scales by the
    // stride (the matrix on the right, the planes' normals), so the cells land where the
    // level's cells are. A last cell shorter than the stride (an axis of n points with
    // (n - 1) % stride != 0) is drawn a whole stride long: up to stride - 1 voxels past
    // the volume's far faces, in interactive frames only.
    pyramid = impl.Coarse[static_cast<std::size_t>(frame.Level)].Pyramid.get();
    const double stride = LevelStride(frame.Level);
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        drawn.IndexToView[4 * r + c] *= stride;
      }
    }
    for (std::array<double, 4>& plane : drawn.ClipPlanes)
    {
      for (int c = 0; c < 3; ++c)
      {
        plane[c] *= stride;
      }
    }
  }
  IsosurfaceFrameStats frameStats;
  if (!impl.Renderer->Render(*pyramid, drawn, frameStats, error))
  {
    return false;
  }
  stats.Level = frame.Level;
  stats.Primitives = frameStats.Primitives;
  stats.PointFootprint = frameStats.PointFootprint;
  stats.FirstHit = frameStats.FirstHit;
  stats.SampleDistance = frameStats.SampleDistance;
  return true;
}

//------------------------------------------------------------------------------
const IsosurfaceSceneStats& IsosurfaceScene::GetStats() const
{
  return this->Impl->Stats;
}

std::uint64_t IsosurfaceScene::GetActivePairs() const
{
  const Internals& impl = *this->Impl;
  return impl.Pyramid && impl.Pyramid->IsBuilt() && !impl.BuiltValues.empty()
    ? impl.Pyramid->GetTotal()
    : 0;
}

std::uint64_t IsosurfaceScene::GetActivePairs(int level) const
{
  const Internals& impl = *this->Impl;
  if (level == FullLevel)
  {
    return this->GetActivePairs();
  }
  if (level < 0 || level > FullLevel)
  {
    return 0;
  }
  const Internals::CoarseLevel& coarse = impl.Coarse[static_cast<std::size_t>(level)];
  return coarse.Pyramid && coarse.Pyramid->IsBuilt() && !coarse.BuiltValues.empty() &&
      coarse.BuiltValues == impl.Values()
    ? coarse.Pyramid->GetTotal()
    : 0;
}

std::uint64_t IsosurfaceScene::EstimateActivePairs(std::uint64_t fullPairs, int level)
{
  if (level >= FullLevel || fullPairs == 0)
  {
    return fullPairs;
  }
  const std::uint64_t stride = static_cast<std::uint64_t>(LevelStride(std::max(level, 0)));
  return std::max<std::uint64_t>(1, fullPairs / (stride * stride));
}

std::array<int, 3> IsosurfaceScene::LevelDimensions(const int points[3], int level)
{
  const int stride = LevelStride(std::max(0, std::min(level, FullLevel)));
  std::array<int, 3> dims = { { 0, 0, 0 } };
  for (int a = 0; a < 3; ++a)
  {
    // Every stride-th point, and the last when it is not one of them.
    dims[a] = points[a] < 1 ? 0 : (points[a] - 1) / stride + 1 + ((points[a] - 1) % stride ? 1 : 0);
  }
  return dims;
}

std::uint64_t IsosurfaceScene::GetGPUMemoryBytes() const
{
  const Internals& impl = *this->Impl;
  std::uint64_t bytes = impl.Pyramid ? impl.Pyramid->GetGPUMemoryBytes() : 0;
  for (const Internals::CoarseLevel& c : impl.Coarse)
  {
    bytes += c.Pyramid ? c.Pyramid->GetGPUMemoryBytes() : 0;
  }
  return bytes;
}

std::array<int, 3> IsosurfaceScene::VolumeTextureSize(const int points[3])
{
  return HistoPyramidGL::VolumeTextureSize(points);
}

std::uint64_t IsosurfaceScene::EstimateGPUMemoryBytes(ScalarType type, const int points[3])
{
  return HistoPyramidGL::EstimateGPUMemoryBytes(type, points);
}

std::uint64_t IsosurfaceScene::GetFrameBufferBytes() const
{
  return this->Impl->Renderer ? this->Impl->Renderer->GetFrameBufferBytes() : 0;
}

} // namespace mediso
