// SPDX-License-Identifier: BSD-3-Clause
#include "IsosurfaceScene.h"

#include "BlockLOD.h" // MakeCoarseCopy, LevelStride
#include "BrickGrid.h"
#include "GLApi.h"
#include "HistoPyramidGL.h"
#include "IsosurfaceRendererGL.h"
#include "Matrix4.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <new>
#include <sstream>
#include <unordered_map>
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

// The full level (the volume itself) and the coarse ones below it, as Block LOD numbers them,
// down to the scene's own CoarsestLevel (-1).
constexpr int FullLevel = NumberOfLevels - 1;
constexpr int CoarseLevels = FullLevel - IsosurfaceScene::CoarsestLevel;

// Points a brick's texture holds: the points its cells and their gradients read.
constexpr int BrickApron = 1;

std::string Megabytes(std::uint64_t bytes)
{
  std::ostringstream text;
  text.precision(3);
  text << static_cast<double>(bytes) / 1e6 << " MB";
  return text.str();
}

// The isovalues of `values` that cross `range` (min < iso <= max), in order.
std::vector<double> Crossing(const BrickRange& range, const std::vector<double>& values)
{
  std::vector<double> crossing;
  for (const double v : values)
  {
    if (range.Min < v && v <= range.Max)
    {
      crossing.push_back(v);
    }
  }
  return crossing;
}

// "2x", "1.5x": a ratio as the reasons say it.
std::string RatioText(double ratio)
{
  std::ostringstream text;
  text << ratio << "x";
  return text.str();
}

std::string Size(const int points[3])
{
  return std::to_string(points[0]) + "x" + std::to_string(points[1]) + "x" +
    std::to_string(points[2]);
}
} // namespace

//------------------------------------------------------------------------------
struct IsosurfaceScene::Internals
{
  GLParallelFor Parallel;
  std::shared_ptr<const GLApi> GL;
  std::unique_ptr<HistoPyramidGL> Pyramid;
  std::unique_ptr<IsosurfaceRendererGL> Renderer;
  HitCull HitCullMode = HitCull::Auto; // SetHitCull(), kept across contexts

  // What the uploaded volume and the built pyramid were made from.
  bool HasVolume = false;
  VolumeDescription Volume;
  std::vector<double> BuiltValues;

  // The coarse levels (index = level - CoarsestLevel, levels -1 to 2: At()): made on a level's
  // first frame, forgotten with the volume.
  struct CoarseLevel
  {
    std::unique_ptr<HistoPyramidGL> Pyramid;
    std::vector<double> BuiltValues;
  };
  std::array<CoarseLevel, CoarseLevels> Coarse;
  // A coarse level's samples from the host (SetCoarseSource(); null Data: sampled here).
  std::array<VolumeDescription, CoarseLevels> CoarseSources;
  static std::size_t At(int level)
  {
    return static_cast<std::size_t>(level - IsosurfaceScene::CoarsestLevel);
  }

  // Streaming (BeginStreaming()): the runs of BlockCells points per axis that hold their values.
  struct Streaming
  {
    bool On = false;
    int Runs[3] = { 0, 0, 0 };
    std::vector<std::uint8_t> Resident;
    std::int64_t Missing = 0;
  };
  Streaming Stream;
  // Whether every point of [first, last] has arrived.
  bool PointsHaveArrived(const int first[3], const int last[3]) const;
  // A coarse level's texture, from the host's samples or the volume's.
  bool UploadCoarse(int level, std::string& error);

  std::vector<IsosurfaceLook> Surfaces;
  IsosurfaceSceneStats Stats;

  // `frame` as its level's pyramid is drawn: the scene's surfaces, and on a coarse level the
  // index space scaled by the level's stride. Coarse point c stands for the volume's point
  // stride * c: the index space scales by the stride (the matrix on the right, the planes'
  // normals), so the cells land where the level's cells are. A last cell shorter than the
  // stride (an axis of n points with (n - 1) % stride != 0) is drawn a whole stride long: up to
  // stride - 1 voxels past the volume's far faces, in interactive frames only.
  IsosurfaceFrame LevelFrame(const IsosurfaceFrame& frame) const
  {
    IsosurfaceFrame drawn = frame;
    drawn.Surfaces = this->Surfaces;
    if (frame.Level != FullLevel)
    {
      const double stride = VolumeLevelStride(frame.Level);
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
    return drawn;
  }

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

  // Limits (0: the context's, the default budget).
  int MaxTextureSize = 0;
  std::uint64_t Budget = 0;

  // A volume kept as bricks: the grid, each brick's range over the cells it
  // owns, the resident bricks' pyramids, and the bricks of the last build.
  bool Bricked = false;
  std::string BrickReason; // why the volume is not one texture
  BrickGrid Grid;
  std::vector<BrickRange> Ranges;
  BrickResidency Residency;
  std::unordered_map<std::int64_t, std::unique_ptr<HistoPyramidGL>> Bricks;
  // The isovalues of each brick's pyramid, the last build's or those adopted since.
  std::unordered_map<std::int64_t, std::vector<double>> BrickValues;
  std::vector<std::int64_t> Active;

  // The brick pool (SetBrickPool()): the resident bricks in the slots of one
  // texture with one pyramid (PoolBrick: the brick in each slot, -1 for
  // none; PoolOwns: whether the slot's cells count in the current build),
  // least recently used slots given to new bricks (PoolResidency counts
  // slots, one "byte" each). PoolDrawn: the last build used the pool.
  bool UsePool = true;
  std::unique_ptr<HistoPyramidGL> Pool;
  std::vector<std::int64_t> PoolBrick;
  std::vector<char> PoolOwns;
  std::unordered_map<std::int64_t, int> PoolSlot;
  BrickResidency PoolResidency;
  bool PoolDrawn = false;
  // The pool's GPU memory as ChoosePoolSlots() estimated it when it was made,
  // weighed again at every isovalue change (KeepsPool()).
  std::uint64_t PoolBytes = 0;
  // Why the last update of a bricked volume drew its bricks without the
  // pool ("" where the pool held them).
  std::string PoolReason;

  int TextureLimit() const
  {
    const int context = this->GL ? this->GL->GetMax3DTextureSize() : 0;
    return this->MaxTextureSize > 0 ? std::min(this->MaxTextureSize, context) : context;
  }
  std::uint64_t GetBudget() const
  {
    // Half of what the device has leaves the rest to the host's other textures, its frame
    // buffers and other programs.
    const std::uint64_t device = this->GL ? this->GL->GetDeviceMemoryBytes() : 0;
    if (this->Budget > 0)
    {
      return this->Budget;
    }
    return device > 0 ? device / 2 : IsosurfaceScene::DefaultGPUMemoryBudget;
  }
  // The texture of a brick: its cells' points with the apron.
  void BrickTexture(std::int64_t brick, int extent[6], int points[3]) const
  {
    this->Grid.ReadPoints(brick, BrickApron, extent);
    for (int a = 0; a < 3; ++a)
    {
      points[a] = extent[2 * a + 1] - extent[2 * a] + 1;
    }
  }
  std::uint64_t BrickBytes(std::int64_t brick) const
  {
    int extent[6], points[3];
    this->BrickTexture(brick, extent, points);
    return HistoPyramidGL::EstimateGPUMemoryBytes(this->Volume.Type, points);
  }
  void ReleasePool()
  {
    if (this->Pool)
    {
      this->Pool->Release();
    }
    this->Pool.reset();
    this->PoolBrick.clear();
    this->PoolOwns.clear();
    this->PoolSlot.clear();
    this->PoolResidency.Clear();
    this->PoolDrawn = false;
    this->PoolBytes = 0;
    this->Stats.PoolSlots = 0;
  }
  void ReleaseBrickPyramids()
  {
    for (auto& brick : this->Bricks)
    {
      brick.second->Release();
    }
    this->Bricks.clear();
    this->BrickValues.clear();
    this->Residency.Clear();
  }
  void ReleaseBricks()
  {
    this->ReleasePool();
    this->ReleaseBrickPyramids();
    this->Active.clear();
    this->Bricked = false;
    this->Grid = BrickGrid();
    this->Ranges.clear();
    this->Stats.Bricks = this->Stats.ActiveBricks = this->Stats.ResidentBricks = 0;
    this->Stats.BrickPoints = 0;
    this->Stats.OverBudget = false;
    this->PoolReason.clear();
  }
  bool AdoptBricks(const VolumeDescription& volume, const std::string& why, std::string& error);
  bool UpdateBricks(const std::vector<double>& values, std::string& error);
  bool SendBrick(std::int64_t brick, const int extent[6], const int points[3],
    std::vector<unsigned char>& staging, HistoPyramidGL* pyramid, int slot, std::string& error);
  bool UpdatePool(const std::vector<std::int64_t>& active, const std::vector<double>& values,
    bool& held, std::string& error);
  bool ChoosePoolSlots(std::size_t count, int side, int slots[3], std::uint64_t& bytes) const;
  bool KeepsPool(const std::vector<std::int64_t>& active, std::uint64_t own) const;
  std::vector<std::int64_t> VisibilityOrder(const IsosurfaceFrame& frame) const;
  std::vector<IsosurfacePiece> Pieces(const IsosurfaceFrame& frame) const;
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
  if (impl.Renderer)
  {
    impl.Renderer->SetHitCull(impl.HitCullMode);
  }
  impl.Bricks.clear(); // Release()d in their own context before, as the doc asks
  impl.Pool.reset();
  impl.ReleaseBricks();
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
  impl.ReleaseBricks();
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
  impl.ReleaseBricks();
  impl.CoarseSources.fill(VolumeDescription());
  impl.Stream = Internals::Streaming();
  const auto start = Clock::now();
  // One texture where it fits the texture limit and the budget; else bricks.
  std::string why;
  if (!volume.Data || volume.Dims[0] < 2 || volume.Dims[1] < 2 || volume.Dims[2] < 2)
  {
    why = ""; // the upload says what is wrong
  }
  else if (std::max({ PackedVolumeWidth(volume.Dims[0]), volume.Dims[1], volume.Dims[2] }) >
    impl.TextureLimit())
  {
    const auto texture = HistoPyramidGL::VolumeTextureSize(volume.Dims);
    const bool forced =
      impl.MaxTextureSize > 0 && impl.MaxTextureSize < impl.GL->GetMax3DTextureSize();
    why = "the " + Size(volume.Dims) + " volume (a " + std::to_string(texture[0]) + "x" +
      std::to_string(texture[1]) + "x" + std::to_string(texture[2]) +
      " texture) exceeds GL_MAX_3D_TEXTURE_SIZE " + std::to_string(impl.TextureLimit()) +
      (forced ? " (as set)" : "");
  }
  else if (HistoPyramidGL::EstimateGPUMemoryBytes(volume.Type, volume.Dims) > impl.GetBudget())
  {
    why = "the " + Size(volume.Dims) + " volume needs " +
      Megabytes(HistoPyramidGL::EstimateGPUMemoryBytes(volume.Type, volume.Dims)) +
      " of GPU memory in one texture, over the budget of " + Megabytes(impl.GetBudget());
  }
  if (!why.empty())
  {
    impl.Pyramid->Release(); // the one texture of a former volume
    if (!impl.AdoptBricks(volume, why, error))
    {
      return false;
    }
  }
  else if (!impl.Pyramid->UploadVolume(volume.Type, volume.Data, volume.Dims, impl.Parallel, error))
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

void IsosurfaceScene::SetMaxTextureSize(int texels)
{
  if (texels != this->Impl->MaxTextureSize)
  {
    this->Impl->MaxTextureSize = std::max(texels, 0);
    this->Impl->HasVolume = false; // decided again at the next SetVolume()
  }
}

int IsosurfaceScene::GetMaxTextureSize() const
{
  return this->Impl->MaxTextureSize;
}

void IsosurfaceScene::SetGPUMemoryBudget(std::uint64_t bytes)
{
  if (bytes != this->Impl->Budget)
  {
    this->Impl->Budget = bytes;
    this->Impl->HasVolume = false;
  }
}

std::uint64_t IsosurfaceScene::GetGPUMemoryBudget() const
{
  return this->Impl->GetBudget();
}

bool IsosurfaceScene::IsBricked() const
{
  return this->Impl->HasVolume && this->Impl->Bricked;
}

void IsosurfaceScene::SetBrickPool(bool on)
{
  if (on != this->Impl->UsePool)
  {
    this->Impl->UsePool = on;
    this->Impl->HasVolume = false; // decided again at the next SetVolume()
  }
}

bool IsosurfaceScene::GetBrickPool() const
{
  return this->Impl->UsePool;
}

void IsosurfaceScene::SetHitCull(HitCull mode)
{
  this->Impl->HitCullMode = mode;
  if (this->Impl->Renderer)
  {
    this->Impl->Renderer->SetHitCull(mode);
  }
}

HitCull IsosurfaceScene::GetHitCull() const
{
  return this->Impl->HitCullMode;
}

std::string IsosurfaceScene::GetBrickPoolReason() const
{
  return this->IsBricked() ? this->Impl->PoolReason : std::string();
}

int IsosurfaceScene::ChooseBrickPoints(ScalarType type, int maxTextureSize, std::uint64_t budget)
{
  for (int k = 8; k > 4; --k)
  {
    const int edge = (1 << k) - 8;
    // A brick's texture: its points, one more on the + side, the apron on both.
    const int points[3] = { edge + 1 + 2 * BrickApron, edge + 1 + 2 * BrickApron,
      edge + 1 + 2 * BrickApron };
    if (points[0] <= maxTextureSize &&
      HistoPyramidGL::EstimateGPUMemoryBytes(type, points) <= budget / 8)
    {
      return edge;
    }
  }
  return BlockCells;
}

//------------------------------------------------------------------------------
// The volume as bricks: their grid and value ranges (nothing is uploaded yet).
bool IsosurfaceScene::Internals::AdoptBricks(
  const VolumeDescription& volume, const std::string& why, std::string& error)
{
  const int edge = ChooseBrickPoints(volume.Type, this->TextureLimit(), this->GetBudget());
  if (edge + 1 + 2 * BrickApron > this->TextureLimit())
  {
    error = why + ", and a brick of " + std::to_string(edge) + " points does not fit either";
    return false;
  }
  BrickGrid grid(volume.Dims, edge);
  // Each brick's range over its own cells' corners (no apron: the gradients'
  // extra points decide no crossing). Double data is compared on the GPU as
  // float: rounding keeps the order, so the float range is the rounded one.
  std::vector<BrickRange> ranges;
  try
  {
    ranges = ComputeBrickRanges(grid, volume.Type, volume.Data, 0, this->Parallel);
  }
  catch (const std::bad_alloc&)
  {
    error = "memory ran out while finding the volume's bricks";
    return false;
  }
  if (volume.Type == ScalarType::Float64)
  {
    for (BrickRange& r : ranges)
    {
      if (r.Min <= r.Max)
      {
        r.Min = static_cast<float>(r.Min);
        r.Max = static_cast<float>(r.Max);
      }
    }
  }
  this->Bricked = true;
  this->Grid = grid;
  this->Ranges = std::move(ranges);
  this->Residency.SetBudget(this->GetBudget());
  this->Stats.BrickPoints = edge;
  this->Stats.Bricks = static_cast<std::uint64_t>(grid.GetNumberOfBricks());
  this->BrickReason = why;
  return true;
}

// The pyramids of the bricks `values` cross: resident (uploaded where not),
// and built. False, with the reason, where they do not fit the budget.
bool IsosurfaceScene::Internals::UpdateBricks(const std::vector<double>& values, std::string& error)
{
  IsosurfaceSceneStats& stats = this->Stats;
  this->Active.clear(); // until every active brick is built
  this->PoolDrawn = false;
  const std::vector<std::int64_t> active = ActiveBricks(this->Ranges, values);
  std::uint64_t need = 0;
  for (const std::int64_t brick : active)
  {
    need += this->BrickBytes(brick);
  }
  stats.ActiveBricks = active.size();
  stats.OverBudget = need > this->GetBudget();
  if (stats.OverBudget)
  {
    error = this->BrickReason + ": it is kept as bricks, but the " + std::to_string(active.size()) +
      " of its " + std::to_string(this->Grid.GetNumberOfBricks()) +
      " bricks that the isovalues cross need " + Megabytes(need) +
      " of GPU memory, over the budget of " + Megabytes(this->GetBudget());
    // Neither the pool nor the bricks' own pyramids draw them (a pool there
    // is stays for the next isovalues that fit).
    this->PoolReason = "the " + std::to_string(active.size()) + " crossed bricks need " +
      Megabytes(need) + " of GPU memory, over the budget of " + Megabytes(this->GetBudget());
    return false;
  }
  stats.BrickPyramidBuilds = 0;
  this->PoolReason = this->UsePool ? "" : "the brick pool is off";
  if (this->UsePool)
  {
    bool held = false;
    const bool built = this->UpdatePool(active, values, held, error);
    if (held)
    {
      if (built)
      {
        this->Active = active;
      }
      return built;
    }
    // The pool cannot hold them within the limit and the budget, or would
    // cost more than MaximumPoolMemoryRatio times their own pyramids: those.
    this->ReleasePool();
  }
  // Bricks in use first become the most recent, so that only others make room.
  for (const std::int64_t brick : active)
  {
    this->Residency.Touch(brick);
  }
  // Each brick's passes are queued as soon as it is there, and the totals
  // read back after the last: one wait for the GPU per update, and the GPU
  // builds a brick while the next one is cut out and sent.
  stats.BuildTilesDrawn = 0;
  stats.BuildTiles = 0;
  std::vector<unsigned char> staging; // one brick's texture values at a time
  for (const std::int64_t brick : active)
  {
    if (!this->Residency.IsResident(brick))
    {
      std::vector<std::int64_t> evicted;
      if (!this->Residency.MakeResident(brick, this->BrickBytes(brick), evicted))
      {
        error = "a brick of " + std::to_string(this->Grid.GetBrickPoints()) +
          " points exceeds the GPU budget of " + Megabytes(this->GetBudget());
        return false;
      }
      for (const std::int64_t gone : evicted)
      {
        const auto found = this->Bricks.find(gone);
        if (found != this->Bricks.end())
        {
          found->second->Release();
          this->Bricks.erase(found);
        }
        this->BrickValues.erase(gone);
      }
      std::unique_ptr<HistoPyramidGL> pyramid(new HistoPyramidGL(this->GL));
      pyramid->ShareProgramsWith(*this->Pyramid);
      int extent[6], points[3];
      this->BrickTexture(brick, extent, points);
      if (!this->SendBrick(brick, extent, points, staging, pyramid.get(), -1, error))
      {
        this->Residency.Evict(brick);
        return false;
      }
      // Only the cells whose first corner the brick owns count.
      int owned[6];
      this->Grid.OwnedPoints(brick, owned);
      const int first[3] = { owned[0] - extent[0], owned[2] - extent[2], owned[4] - extent[4] };
      const int end[3] = { owned[1] - extent[0] + 1, owned[3] - extent[2] + 1,
        owned[5] - extent[4] + 1 };
      pyramid->SetOwnedCells(first, end);
      this->Bricks[brick] = std::move(pyramid);
      ++stats.BrickUploads;
    }
    // A brick whose pyramid the same of the old and the new isovalues cross
    // keeps it (a value outside the brick's range crosses none of its cells,
    // so every cell counts as it did): a change of one of several surfaces
    // builds only the bricks it touches. With one isovalue, as in a sweep,
    // a brick the new one crosses was crossed by another or by none: built.
    HistoPyramidGL& pyramid = *this->Bricks.at(brick);
    std::vector<double>& builtFor = this->BrickValues[brick];
    const BrickRange& range = this->Ranges[static_cast<std::size_t>(brick)];
    if (pyramid.IsBuilt() && Crossing(range, builtFor) == Crossing(range, values) &&
      pyramid.AdoptIsovalues(values))
    {
      builtFor = values;
      continue;
    }
    builtFor.clear(); // until its build is read back
    if (!pyramid.BuildPasses(values, error))
    {
      return false;
    }
  }
  stats.ResidentBricks = this->Residency.GetNumberOfResidentBricks();
  for (const std::int64_t brick : active)
  {
    HistoPyramidGL& pyramid = *this->Bricks.at(brick);
    std::vector<double>& builtFor = this->BrickValues[brick];
    if (builtFor.empty())
    {
      if (!pyramid.FinishBuild(error))
      {
        return false;
      }
      builtFor = values;
      ++stats.BrickPyramidBuilds;
      stats.BuildTilesDrawn += pyramid.GetLastTilesDrawn();
    }
    stats.BuildTiles += pyramid.GetNumberOfTiles();
  }
  this->Active = active;
  return true;
}

// A brick's texture values (the points of `extent`, with their apron) cut
// out of the host's volume into `staging` and sent: as `pyramid`'s volume,
// or into the pool's slot `slot` where `pyramid` is null. Rows go padded to
// whole texels in the one copy that cuts them out (PackVolumeBox()); double
// values are copied, then converted and padded by the upload.
bool IsosurfaceScene::Internals::SendBrick(std::int64_t brick, const int extent[6],
  const int points[3], std::vector<unsigned char>& staging, HistoPyramidGL* pyramid, int slot,
  std::string& error)
{
  const int bytesPerValue = ScalarTypeSize(this->Volume.Type);
  const bool packed = this->Volume.Type != ScalarType::Float64;
  try
  {
    if (packed)
    {
      PackVolumeBox(
        this->Volume.Data, this->Volume.Dims, extent, bytesPerValue, this->Parallel, staging);
    }
    else
    {
      staging.resize(BrickGrid::ExtentPoints(extent) * bytesPerValue);
      CopyBrick(this->Grid, brick, extent, this->Volume.Data, bytesPerValue, staging.data());
    }
  }
  catch (const std::bad_alloc&)
  {
    error = "memory ran out while copying a brick for the GPU upload";
    return false;
  }
  const int placement[3] = { extent[0], extent[2], extent[4] };
  if (pyramid)
  {
    const ScalarType type = this->Volume.Type;
    return packed ? pyramid->UploadPackedVolume(type, staging.data(), points, this->Parallel, error)
                  : pyramid->UploadVolume(type, staging.data(), points, this->Parallel, error);
  }
  return packed ? this->Pool->UploadPackedSlot(slot, staging.data(), points, placement, error)
                : this->Pool->UploadSlot(slot, staging.data(), points, placement, error);
}

// The slots per axis of a pool for `count` bricks of `side` points a side
// within the texture limit, HistoPyramidGL::MaximumSlots and the budget: the
// fewest bytes among the boxes of the fewest slots, and those bytes. False
// where none holds them.
bool IsosurfaceScene::Internals::ChoosePoolSlots(
  std::size_t count, int side, int slots[3], std::uint64_t& bytes) const
{
  const int limit = this->TextureLimit();
  const int most[3] = { 4 * limit / side, limit / side, limit / side }; // 4 points to a texel in x
  std::uint64_t best = ~std::uint64_t(0);
  long long fewest = -1;
  for (int z = 1; z <= most[2]; ++z)
  {
    for (int y = 1; y <= most[1]; ++y)
    {
      const long long plane = static_cast<long long>(y) * z;
      const long long x = (static_cast<long long>(count) + plane - 1) / plane;
      if (x < 1 || x > most[0] || x * plane > HistoPyramidGL::MaximumSlots)
      {
        continue;
      }
      const int points[3] = { static_cast<int>(x) * side, y * side, z * side };
      const std::uint64_t need = HistoPyramidGL::EstimateGPUMemoryBytes(this->Volume.Type, points);
      if (need > this->GetBudget() || (fewest >= 0 && x * plane > fewest) ||
        (x * plane == fewest && need >= best))
      {
        continue;
      }
      fewest = x * plane;
      best = need;
      slots[0] = static_cast<int>(x);
      slots[1] = y;
      slots[2] = z;
    }
  }
  bytes = best;
  return fewest > 0;
}

// Whether the pool there is stays for the `active` bricks, whose own
// pyramids take `own` bytes: it holds them, within MaximumPoolMemoryRatio of
// `own`, the bound a new pool is made within. A pool made for more bricks
// (room for 32 when 18 were crossed) is otherwise weighed again as a new one
// when the isovalues come to cross fewer or thinner bricks (a smaller pool
// is made, or none), so that whether the pool draws follows the current
// isovalues, not those the pool was made for. No brick crossed keeps none,
// as a scene with no pool yet would decide.
bool IsosurfaceScene::Internals::KeepsPool(
  const std::vector<std::int64_t>& active, std::uint64_t own) const
{
  return this->Pool && !active.empty() &&
    static_cast<std::size_t>(this->Pool->GetNumberOfSlots()) >= active.size() &&
    static_cast<double>(this->PoolBytes) <= MaximumPoolMemoryRatio * static_cast<double>(own);
}

// The active bricks in the pool and the pool's pyramid built over them.
// `held` false (and nothing changed but the pool let go) where the pool
// cannot hold them; else the result is the build's.
bool IsosurfaceScene::Internals::UpdatePool(const std::vector<std::int64_t>& active,
  const std::vector<double>& values, bool& held, std::string& error)
{
  IsosurfaceSceneStats& stats = this->Stats;
  held = false;
  int side = 16;
  while (side < this->Grid.GetBrickPoints() + 1 + 2 * BrickApron)
  {
    side *= 2;
  }
  // A slot is a cube of a power of two: it holds a brick of 2^k - 8 points
  // with a margin (27 points in 32, 59 in 64), but a brick thinner than the
  // slot on an axis (96x96x251 points in 256, a long thin volume's) fills a
  // fraction of it, and the pool's texture and pyramid, cubes of slots, then
  // hold several times the bricks' own pyramids (those of 96x96x251 padded
  // to 128x128x256). The pool is weighed against what the same bricks cost
  // as their own pyramids and made or kept only within
  // MaximumPoolMemoryRatio of it.
  std::uint64_t own = 0;
  for (const std::int64_t brick : active)
  {
    own += this->BrickBytes(brick);
  }
  if (!this->KeepsPool(active, own))
  {
    // Room for the next power of two of bricks where that fits and stays
    // within the ratio: a growing set of bricks then seldom makes a new pool
    // (and uploads every brick again), and the pyramid, whose levels are
    // padded to powers of two, is no larger than for the active bricks alone.
    // Else a pool for the active bricks alone.
    std::size_t room = 1;
    while (room < active.size())
    {
      room *= 2;
    }
    int slots[3] = { 0, 0, 0 };
    std::uint64_t bytes = 0, least = 0;
    std::size_t leastSlots = 0;
    bool chosen = false;
    for (const std::size_t count : { room, active.size() })
    {
      if (count == 0 || !this->ChoosePoolSlots(count, side, slots, bytes))
      {
        continue;
      }
      if (leastSlots == 0 || bytes < least)
      {
        least = bytes;
        leastSlots = static_cast<std::size_t>(slots[0]) * slots[1] * slots[2];
      }
      if (static_cast<double>(bytes) <= MaximumPoolMemoryRatio * static_cast<double>(own))
      {
        chosen = true;
        break;
      }
    }
    if (!chosen)
    {
      if (active.empty())
      {
        this->PoolReason = "no brick is crossed";
      }
      else if (leastSlots == 0)
      {
        this->PoolReason = "a pool of " + std::to_string(side) + "-point slots for the " +
          std::to_string(active.size()) + " crossed bricks exceeds the texture limit of " +
          std::to_string(this->TextureLimit()) + " or the budget of " +
          Megabytes(this->GetBudget());
      }
      else
      {
        this->PoolReason = "a pool of " + std::to_string(leastSlots) + " slots of " +
          std::to_string(side) + " points would take " + Megabytes(least) +
          " of GPU memory, over " + RatioText(MaximumPoolMemoryRatio) + " the " + Megabytes(own) +
          " of the " + std::to_string(active.size()) + " crossed bricks' own pyramids";
      }
      return false;
    }
    this->ReleasePool();
    this->Pool.reset(new HistoPyramidGL(this->GL));
    const int cells[3] = { this->Volume.Dims[0] - 1, this->Volume.Dims[1] - 1,
      this->Volume.Dims[2] - 1 };
    std::string why;
    if (!this->Pool->AllocatePool(this->Volume.Type, side, slots, cells, this->Parallel, why))
    {
      this->ReleasePool(); // a context that cannot make it: the bricks' own pyramids
      this->PoolReason = "the context cannot make the pool: " + why;
      return false;
    }
    this->Pool->ShareProgramsWith(*this->Pyramid); // after the allocation, which starts afresh
    const std::size_t count = static_cast<std::size_t>(slots[0]) * slots[1] * slots[2];
    this->PoolBrick.assign(count, -1);
    this->PoolOwns.assign(count, 0);
    this->PoolResidency.SetBudget(count);
    this->PoolBytes = bytes;
    stats.PoolSlots = count;
  }
  held = true;
  this->ReleaseBrickPyramids(); // the pool holds the bricks now
  stats.ResidentBricks = 0;
  // Bricks in use first become the most recent, so that only others give up their slots.
  for (const std::int64_t brick : active)
  {
    this->PoolResidency.Touch(brick);
  }
  std::vector<unsigned char> staging; // one brick's texture values at a time
  for (const std::int64_t brick : active)
  {
    if (this->PoolResidency.IsResident(brick))
    {
      continue;
    }
    std::vector<std::int64_t> evicted;
    this->PoolResidency.MakeResident(brick, 1, evicted);
    for (const std::int64_t gone : evicted)
    {
      const auto found = this->PoolSlot.find(gone);
      if (found != this->PoolSlot.end())
      {
        this->PoolBrick[static_cast<std::size_t>(found->second)] = -1;
        this->PoolSlot.erase(found);
      }
    }
    const auto free = std::find(this->PoolBrick.begin(), this->PoolBrick.end(), -1);
    const int slot = static_cast<int>(free - this->PoolBrick.begin());
    int extent[6], points[3];
    this->BrickTexture(brick, extent, points);
    if (free == this->PoolBrick.end() ||
      !this->SendBrick(brick, extent, points, staging, nullptr, slot, error))
    {
      this->PoolResidency.Evict(brick);
      error = error.empty() ? "the brick pool has no free slot" : error;
      return false;
    }
    this->PoolBrick[static_cast<std::size_t>(slot)] = brick;
    this->PoolOwns[static_cast<std::size_t>(slot)] = 0; // UploadSlot() leaves it owning nothing
    this->PoolSlot[brick] = slot;
    ++stats.BrickUploads;
  }
  // Each slot's cells count where its brick is active: the cells the brick owns.
  std::vector<char> isActive(this->PoolBrick.size(), 0);
  for (const std::int64_t brick : active)
  {
    isActive[static_cast<std::size_t>(this->PoolSlot.at(brick))] = 1;
  }
  for (std::size_t slot = 0; slot < this->PoolBrick.size(); ++slot)
  {
    if (isActive[slot] == this->PoolOwns[slot])
    {
      continue;
    }
    int first[3] = { 0, 0, 0 }, end[3] = { 0, 0, 0 };
    if (isActive[slot])
    {
      int extent[6], points[3], owned[6];
      const std::int64_t brick = this->PoolBrick[slot];
      this->BrickTexture(brick, extent, points);
      this->Grid.OwnedPoints(brick, owned);
      for (int a = 0; a < 3; ++a)
      {
        first[a] = owned[2 * a] - extent[2 * a];
        end[a] = owned[2 * a + 1] - extent[2 * a] + 1;
      }
    }
    this->Pool->SetSlotCells(static_cast<int>(slot), first, end);
    this->PoolOwns[slot] = isActive[slot];
  }
  stats.ResidentBricks = this->PoolResidency.GetNumberOfResidentBricks();
  if (!this->Pool->Build(values, error))
  {
    return false;
  }
  stats.BuildTilesDrawn = this->Pool->GetLastTilesDrawn();
  stats.BuildTiles = this->Pool->GetNumberOfTiles();
  stats.BrickPyramidBuilds = 1;
  this->PoolDrawn = true;
  return true;
}

// The built bricks with something to draw, in a visibility order for the
// frame's eye: by the sum over the axes of how many bricks lie between a
// brick and the eye's brick. Along a ray from the eye every coordinate moves
// away from the eye's, so a brick in front of another is nearer on every
// axis and strictly on one: nearest first, or farthest first for
// translucent surfaces.
std::vector<std::int64_t> IsosurfaceScene::Internals::VisibilityOrder(
  const IsosurfaceFrame& frame) const
{
  int eyeBrick[3] = { 0, 0, 0 };
  matrix4::Matrix viewToIndex;
  if (matrix4::Invert(matrix4::FromArray(frame.IndexToView), viewToIndex))
  {
    const double eyeView[4] = { 0.0, 0.0, frame.Parallel ? 1.0 : 0.0, frame.Parallel ? 0.0 : 1.0 };
    const auto eye = matrix4::Transform(viewToIndex, eyeView);
    for (int a = 0; a < 3; ++a)
    {
      const int last = this->Grid.GetBricksPerAxis()[a] - 1;
      eyeBrick[a] = frame.Parallel
        ? (eye[a] > 0.0 ? last : 0)
        : static_cast<int>(std::max(0.0,
            std::min(static_cast<double>(last), std::floor(eye[a] / this->Grid.GetBrickPoints()))));
    }
  }
  bool translucent = false;
  for (const IsosurfaceLook& s : this->Surfaces)
  {
    translucent = translucent || s.Opacity < 1.0f;
  }
  std::vector<std::pair<int, std::int64_t>> order;
  for (const std::int64_t brick : this->Active)
  {
    int index[3];
    this->Grid.BrickIndex(brick, index);
    const int steps = std::abs(index[0] - eyeBrick[0]) + std::abs(index[1] - eyeBrick[1]) +
      std::abs(index[2] - eyeBrick[2]);
    order.emplace_back(translucent ? -steps : steps, brick);
  }
  std::sort(order.begin(), order.end());
  std::vector<std::int64_t> bricks;
  for (const auto& entry : order)
  {
    bricks.push_back(entry.second);
  }
  return bricks;
}

// The built bricks with something to draw, as pieces in visibility order.
std::vector<IsosurfacePiece> IsosurfaceScene::Internals::Pieces(const IsosurfaceFrame& frame) const
{
  std::vector<IsosurfacePiece> pieces;
  for (const std::int64_t brick : this->VisibilityOrder(frame))
  {
    const auto found = this->Bricks.find(brick);
    if (found == this->Bricks.end() || found->second->GetTotal() == 0)
    {
      continue;
    }
    IsosurfacePiece piece;
    piece.Pyramid = found->second.get();
    int extent[6], points[3];
    this->BrickTexture(brick, extent, points);
    piece.Offset[0] = extent[0];
    piece.Offset[1] = extent[2];
    piece.Offset[2] = extent[4];
    pieces.push_back(piece);
  }
  return pieces;
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
  if (impl.Bricked)
  {
    if (!impl.UpdateBricks(values, error))
    {
      return false;
    }
  }
  else
  {
    if (!impl.Pyramid->Build(values, error))
    {
      return false;
    }
    impl.Stats.BuildTilesDrawn = impl.Pyramid->GetLastTilesDrawn();
    impl.Stats.BuildTiles = impl.Pyramid->GetNumberOfTiles();
  }
  // Build() ends by reading the total back: the passes are done.
  impl.Stats.BuildSeconds = Seconds(Clock::now() - start);
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
  if (level < CoarsestLevel || level > FullLevel)
  {
    error = "no volume level " + std::to_string(level) + " (levels are -1 to 3)";
    return false;
  }
  std::vector<double> values = impl.Values();
  Internals::CoarseLevel& coarse = impl.Coarse[Internals::At(level)];
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
  if ((!coarse.Pyramid || !coarse.Pyramid->HasVolume()) && !impl.UploadCoarse(level, error))
  {
    return false;
  }
  if (!coarse.Pyramid->Build(values, error))
  {
    return false;
  }
  ++impl.Stats.CoarseBuilds;
  coarse.BuiltValues = std::move(values);
  return true;
}

// The level's samples: the host's (SetCoarseSource()), else the volume's as vtkBlockLODContour's
// level reads them, a copy the texture takes, not kept (the host's values are the source of
// every level). A streaming volume's values are not all there: only a host's samples then.
bool IsosurfaceScene::Internals::UploadCoarse(int level, std::string& error)
{
  CoarseLevel& coarse = this->Coarse[At(level)];
  const VolumeDescription& source = this->CoarseSources[At(level)];
  coarse.Pyramid.reset(new HistoPyramidGL(this->GL));
  // The build passes' programs depend on the value type only, so a level compiles none that the
  // volume's pyramid compiled (the first build of a coarse level, a change's first answer or a
  // drag's level made ready ahead, was mostly compilation on a software rasteriser).
  if (this->Pyramid)
  {
    coarse.Pyramid->ShareProgramsWith(*this->Pyramid);
  }
  bool uploaded = false;
  if (source.Data)
  {
    uploaded =
      coarse.Pyramid->UploadVolume(source.Type, source.Data, source.Dims, this->Parallel, error);
  }
  else if (this->Stream.On)
  {
    error = "volume level " + std::to_string(level) +
      " samples every point, and the streaming volume's have not all arrived";
  }
  else
  {
    VisitScalarType(this->Volume.Type,
      [&](auto zero)
      {
        using T = decltype(zero);
        mediso::Volume<T> full;
        full.Data = static_cast<const T*>(this->Volume.Data);
        std::copy(this->Volume.Dims, this->Volume.Dims + 3, full.Dims);
        std::vector<T> samples;
        const mediso::Volume<T> sampled =
          MakeStrideCopy(full, VolumeLevelStride(level), samples, SerialIfEmpty(this->Parallel));
        uploaded = coarse.Pyramid->UploadVolume(
          this->Volume.Type, samples.data(), sampled.Dims, this->Parallel, error);
      });
  }
  if (!uploaded)
  {
    coarse.Pyramid.reset();
  }
  return uploaded;
}

bool IsosurfaceScene::SetCoarseSource(
  int level, const VolumeDescription& samples, std::string& error)
{
  Internals& impl = *this->Impl;
  if (level < CoarsestLevel || level >= FullLevel)
  {
    error = "no coarse volume level " + std::to_string(level) + " (coarse levels are -1 to 2)";
    return false;
  }
  if (samples.Data && (samples.Dims[0] < 2 || samples.Dims[1] < 2 || samples.Dims[2] < 2))
  {
    error = "a coarse level's samples need at least 2 points per axis, not " + Size(samples.Dims);
    return false;
  }
  impl.CoarseSources[Internals::At(level)] = samples;
  Internals::CoarseLevel& coarse = impl.Coarse[Internals::At(level)];
  if (coarse.Pyramid)
  {
    coarse.Pyramid->Release();
  }
  coarse.Pyramid.reset();
  coarse.BuiltValues.clear();
  return true;
}

//------------------------------------------------------------------------------
bool IsosurfaceScene::Internals::PointsHaveArrived(const int first[3], const int last[3]) const
{
  if (!this->Stream.On)
  {
    return true;
  }
  int r0[3], r1[3];
  for (int a = 0; a < 3; ++a)
  {
    r0[a] = std::max(0, first[a]) / BlockCells;
    r1[a] = std::min(this->Volume.Dims[a] - 1, last[a]) / BlockCells;
  }
  for (int z = r0[2]; z <= r1[2]; ++z)
  {
    for (int y = r0[1]; y <= r1[1]; ++y)
    {
      for (int x = r0[0]; x <= r1[0]; ++x)
      {
        if (!this->Stream.Resident[(static_cast<std::size_t>(z) * this->Stream.Runs[1] + y) *
                this->Stream.Runs[0] +
              x])
        {
          return false;
        }
      }
    }
  }
  return true;
}

bool IsosurfaceScene::BeginStreaming(std::string& error)
{
  Internals& impl = *this->Impl;
  if (!impl.HasVolume)
  {
    error = "streaming needs a volume first";
    return false;
  }
  if (impl.Bricked)
  {
    error = impl.BrickReason + ": it is kept as bricks, which read the values as they become " +
      "active, so it does not stream";
    return false;
  }
  Internals::Streaming stream;
  stream.On = true;
  std::size_t runs = 1;
  for (int a = 0; a < 3; ++a)
  {
    stream.Runs[a] = (impl.Volume.Dims[a] + BlockCells - 1) / BlockCells;
    runs *= static_cast<std::size_t>(stream.Runs[a]);
  }
  try
  {
    stream.Resident.assign(runs, 0);
  }
  catch (const std::bad_alloc&)
  {
    error = "memory ran out while keeping the streaming volume's residency";
    return false;
  }
  stream.Missing = static_cast<std::int64_t>(runs);
  impl.Stream = std::move(stream);
  impl.Pyramid->EmptyTiles();
  impl.BuiltValues.clear();
  for (int level = CoarsestLevel; level < FullLevel; ++level)
  {
    // Levels -1, 1 and 2 were sampled from values that have not arrived (level 0 is the
    // server's, SetCoarseSource()).
    if (level != 0 && !impl.CoarseSources[Internals::At(level)].Data)
    {
      this->SetCoarseSource(level, VolumeDescription(), error);
    }
  }
  return true;
}

bool IsosurfaceScene::RegionArrived(const int first[3], const int last[3], std::string& error)
{
  Internals& impl = *this->Impl;
  if (!impl.Stream.On)
  {
    error = "the volume is not streaming";
    return false;
  }
  Internals::Streaming& stream = impl.Stream;
  // The runs the region covers whole, per axis: [r0, r1] (BlockLODVolume::RegionArrived's rule).
  int r0[3], r1[3];
  for (int a = 0; a < 3; ++a)
  {
    const int n = impl.Volume.Dims[a];
    const int lo = std::max(0, first[a]);
    const int hi = std::min(n - 1, last[a]);
    if (lo > hi)
    {
      error = "the region is outside the volume";
      return false;
    }
    r0[a] = (lo + BlockCells - 1) / BlockCells;
    r1[a] = hi == n - 1 ? stream.Runs[a] - 1 : (hi + 1) / BlockCells - 1;
  }
  for (int z = r0[2]; z <= r1[2]; ++z)
  {
    for (int y = r0[1]; y <= r1[1]; ++y)
    {
      for (int x = r0[0]; x <= r1[0]; ++x)
      {
        std::uint8_t& run =
          stream.Resident[(static_cast<std::size_t>(z) * stream.Runs[1] + y) * stream.Runs[0] + x];
        stream.Missing -= run ? 0 : 1;
        run = 1;
      }
    }
  }
  const Internals* self = &impl;
  if (!impl.Pyramid->UploadRegion(
        impl.Volume.Data, first, last,
        [self](const int a[3], const int b[3]) { return self->PointsHaveArrived(a, b); }, error))
  {
    return false;
  }
  impl.BuiltValues.clear(); // built again when next drawn
  ++impl.Stats.RegionUploads;
  return true;
}

bool IsosurfaceScene::EndStreaming(std::string& error)
{
  Internals& impl = *this->Impl;
  if (!impl.Stream.On)
  {
    return true;
  }
  const bool whole = impl.Stream.Missing == 0;
  impl.Stream = Internals::Streaming();
  for (int level = CoarsestLevel; level < FullLevel; ++level)
  {
    this->SetCoarseSource(level, VolumeDescription(), error);
  }
  if (whole)
  {
    return true;
  }
  // Some points never came through RegionArrived(): the whole texture from the host's values.
  impl.BuiltValues.clear();
  if (!impl.Pyramid->UploadVolume(
        impl.Volume.Type, impl.Volume.Data, impl.Volume.Dims, impl.Parallel, error))
  {
    impl.HasVolume = false;
    return false;
  }
  ++impl.Stats.VolumeUploads;
  return true;
}

bool IsosurfaceScene::IsStreaming() const
{
  return this->Impl->Stream.On;
}

bool IsosurfaceScene::Render(const IsosurfaceFrame& frame, std::string& error)
{
  Internals& impl = *this->Impl;
  IsosurfaceSceneStats& stats = impl.Stats;
  stats.Primitives = 0;
  stats.PointFootprint = false;
  stats.FirstHit = false;
  stats.HitCull = false;
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
  const IsosurfaceFrame drawn = impl.LevelFrame(frame);
  const HistoPyramidGL* pyramid = frame.Level == FullLevel
    ? impl.Pyramid.get()
    : impl.Coarse[Internals::At(frame.Level)].Pyramid.get();
  IsosurfaceFrameStats frameStats;
  // A bricked volume's full level is drawn from the pool, its slots in the
  // bricks' visibility order, or brick by brick; its coarse levels are one texture each.
  bool rendered = false;
  if (impl.Bricked && frame.Level == FullLevel && impl.PoolDrawn)
  {
    std::vector<int> slots;
    for (const std::int64_t brick : impl.VisibilityOrder(frame))
    {
      slots.push_back(impl.PoolSlot.at(brick));
    }
    impl.Pool->SetSlotOrder(slots);
    rendered = impl.Renderer->Render(*impl.Pool, drawn, frameStats, error);
  }
  else
  {
    rendered = impl.Bricked && frame.Level == FullLevel
      ? impl.Renderer->Render(impl.Pieces(frame), drawn, frameStats, error)
      : impl.Renderer->Render(*pyramid, drawn, frameStats, error);
  }
  if (!rendered)
  {
    return false;
  }
  stats.Level = frame.Level;
  stats.Primitives = frameStats.Primitives;
  stats.PointFootprint = frameStats.PointFootprint;
  stats.FirstHit = frameStats.FirstHit;
  stats.HitCull = frameStats.HitCull;
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
  if (impl.BuiltValues.empty())
  {
    return 0;
  }
  if (impl.Bricked && impl.PoolDrawn)
  {
    return impl.Pool->GetTotal();
  }
  if (impl.Bricked)
  {
    std::uint64_t total = 0;
    for (const std::int64_t brick : impl.Active)
    {
      total += impl.Bricks.at(brick)->GetTotal();
    }
    return total;
  }
  return impl.Pyramid && impl.Pyramid->IsBuilt() ? impl.Pyramid->GetTotal() : 0;
}

std::uint64_t IsosurfaceScene::GetActivePairs(int level) const
{
  const Internals& impl = *this->Impl;
  if (level == FullLevel)
  {
    return this->GetActivePairs();
  }
  if (level < CoarsestLevel || level > FullLevel)
  {
    return 0;
  }
  const Internals::CoarseLevel& coarse = impl.Coarse[Internals::At(level)];
  return coarse.Pyramid && coarse.Pyramid->IsBuilt() && !coarse.BuiltValues.empty() &&
      coarse.BuiltValues == impl.Values()
    ? coarse.Pyramid->GetTotal()
    : 0;
}

std::uint64_t IsosurfaceScene::GetProgramBuilds() const
{
  return this->Impl->Renderer ? this->Impl->Renderer->GetProgramBuilds() : 0;
}

int IsosurfaceScene::ProgramsToBuild(const IsosurfaceFrame& frame) const
{
  const Internals& impl = *this->Impl;
  if (impl.Surfaces.empty() || !impl.HasVolume || frame.Level < CoarsestLevel ||
    frame.Level > FullLevel)
  {
    return 0; // Render() draws nothing, or fails, without compiling
  }
  std::vector<double> values = impl.Values();
  const bool full = frame.Level == FullLevel;
  // The variant depends on the pyramid's counted isovalues and walk: known once the level is
  // built for these surfaces. A bricked full level is drawn from pieces or the pool (each its
  // own walk), which this does not follow.
  const HistoPyramidGL* pyramid =
    full ? impl.Pyramid.get() : impl.Coarse[Internals::At(frame.Level)].Pyramid.get();
  const std::vector<double>& built =
    full ? impl.BuiltValues : impl.Coarse[Internals::At(frame.Level)].BuiltValues;
  if (!pyramid || built != values || (full && impl.Bricked))
  {
    return -1;
  }
  if (!impl.Renderer)
  {
    return pyramid->GetTotal() > 0 ? 1 : 0;
  }
  return impl.Renderer->ProgramsToBuild(*pyramid, impl.LevelFrame(frame));
}

std::vector<double> IsosurfaceScene::GetBuiltValues(int level) const
{
  const Internals& impl = *this->Impl;
  if (level == FullLevel)
  {
    return impl.BuiltValues;
  }
  if (level < CoarsestLevel || level > FullLevel)
  {
    return {};
  }
  const Internals::CoarseLevel& coarse = impl.Coarse[Internals::At(level)];
  return coarse.Pyramid && coarse.Pyramid->IsBuilt() ? coarse.BuiltValues : std::vector<double>();
}

std::uint64_t IsosurfaceScene::EstimateActivePairs(std::uint64_t fullPairs, int level)
{
  if (level >= FullLevel || fullPairs == 0)
  {
    return fullPairs;
  }
  const std::uint64_t stride =
    static_cast<std::uint64_t>(VolumeLevelStride(std::max(level, CoarsestLevel)));
  return std::max<std::uint64_t>(1, fullPairs / (stride * stride));
}

int IsosurfaceScene::VolumeLevelStride(int level)
{
  if (level == CoarsestLevel)
  {
    return 2 * LevelStride(0);
  }
  return level >= 0 && level <= FullLevel ? LevelStride(level) : 0;
}

std::array<int, 3> IsosurfaceScene::LevelDimensions(const int points[3], int level)
{
  const int stride = VolumeLevelStride(std::max(CoarsestLevel, std::min(level, FullLevel)));
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
  for (const auto& brick : impl.Bricks)
  {
    bytes += brick.second->GetGPUMemoryBytes();
  }
  bytes += impl.Pool ? impl.Pool->GetGPUMemoryBytes() : 0;
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
