// SPDX-License-Identifier: BSD-3-Clause
// Unit test of the VTK-free CPU surfaces unit (Filters/Core/BlockLODSurfaces.h)
// on small synthetic volumes with the tests' own case table (FanCaseTable.h),
// the host's surfaces plain vectors:
// - a fixed level: one extraction per isovalue, the surface the size its plan
//   counted, the estimate exact afterwards; asked again, a cache hit that
//   allocates nothing and returns the same surface, and 0 predicted seconds;
// - the cost model gets a record only from an update that extracted and did
//   no one-time work (a new volume, a level's first coarse copy);
// - AutoLOD: the highest level whose estimate fits; an estimate below the
//   exact bytes plans the level, drops it and makes the next coarser one;
//   a budget below level 0 makes nothing (binding) or level 0 (guiding);
// - the cache limit evicts the least recently used pairs, never the current
//   ones; a new volume empties it; a host that cannot allocate, or aborts,
//   ends the update with nothing made;
// - a host that recycles the surfaces the cache drops: the same pairs are
//   cached as without it, each dropped surface offered once, before the
//   allocation that needs its room.
#include "BlockLODSurfaces.h"
#include "FanCaseTable.h"
#include "MedicalTestUtilities.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using mediso::LevelChoice;
using Outcome = mediso::SurfacesUpdate::Outcome;

struct Mesh
{
  std::vector<float> Points, Normals;
  std::vector<std::int32_t> Triangles;
};
using MeshRef = std::shared_ptr<Mesh>;
using Surfaces = mediso::BlockLODSurfaces<MeshRef>;

// Counts the host's allocations (an extraction allocates one surface).
struct Maker
{
  int Allocations = 0;
  bool Fail = false;
  mediso::SurfaceMaker<MeshRef> Make()
  {
    mediso::SurfaceMaker<MeshRef> maker;
    maker.Allocate = [this](const mediso::SurfaceKey&, std::int64_t points, std::int64_t triangles,
                       MeshRef& mesh, mediso::SurfaceTarget& target)
    {
      ++this->Allocations;
      if (this->Fail)
      {
        return false;
      }
      mesh = std::make_shared<Mesh>();
      mesh->Points.resize(3 * points);
      mesh->Normals.resize(3 * points);
      mesh->Triangles.resize(3 * triangles);
      target.Narrow.Points = mesh->Points.data();
      target.Narrow.Normals = mesh->Normals.data();
      target.Narrow.Connectivity = mesh->Triangles.data();
      return true;
    };
    return maker;
  }
};

// A sphere's distance field (radius r at the centre), plus `noise` times a
// deterministic pseudo-random value per voxel.
std::vector<float> Field(int n, double radius, double noise)
{
  std::vector<float> values(static_cast<std::size_t>(n) * n * n);
  std::uint32_t state = 2463534242u;
  std::size_t id = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i, ++id)
      {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        const double u = (state & 0xFFFFFF) / double(0xFFFFFF) - 0.5;
        const double x = i - 0.5 * n + 0.3, y = j - 0.5 * n + 0.1, z = k - 0.5 * n + 0.2;
        values[id] = static_cast<float>(std::sqrt(x * x + y * y + z * z) - radius + noise * u);
      }
  return values;
}

mediso::VolumeDescription Describe(const std::vector<float>& values, int n, std::uint64_t stamp)
{
  mediso::VolumeDescription d;
  d.Type = mediso::ScalarType::Float32;
  d.Data = values.data();
  d.Dims[0] = d.Dims[1] = d.Dims[2] = n;
  d.Stamp = stamp;
  return d;
}

LevelChoice Fixed(int level)
{
  LevelChoice choice;
  choice.Level = level;
  return choice;
}

LevelChoice Auto(double budget, bool binds = true)
{
  LevelChoice choice;
  choice.Level = LevelChoice::Auto;
  choice.BudgetBytes = budget;
  choice.BudgetBinds = binds;
  return choice;
}

std::string Num(double v)
{
  return std::to_string(v);
}

void TestFixedLevelAndCache()
{
  const int n = 40;
  const std::vector<float> values = Field(n, 12.0, 0.0);
  auto costs = std::make_shared<mediso::SharedCostModel>();
  Surfaces unit(medical_test::FanCases.Cases, mediso::SerialFor, costs);
  unit.SetCacheLimit(1e9);
  Check(unit.SetVolume(Describe(values, n, 1)), "a first volume is new");
  Maker maker;

  // Level 3: one extraction, the surface its plan counted.
  mediso::SurfacesUpdate u = unit.Update({ 0.0 }, Fixed(3), maker.Make());
  Check(u.Status == Outcome::Done && u.Level == 3, "a fixed level 3 is made");
  Check(u.Extractions == 1 && u.CacheHits == 0 && maker.Allocations == 1,
    "one extraction, one allocation: " + Num(u.Extractions) + ", " + Num(maker.Allocations));
  Check(unit.GetSurfaces().size() == 1, "one surface per isovalue");
  const MeshRef first = unit.GetSurfaces().at(0);
  const mediso::SurfaceEstimate e = unit.Estimate(0.0, 3);
  Check(e.Method == mediso::EstimateMethod::Exact, "the planned pair's estimate is exact");
  Check(first->Triangles.size() == 3 * static_cast<std::size_t>(e.Counts.Triangles) &&
      first->Points.size() == 3 * static_cast<std::size_t>(e.Counts.Points) &&
      e.Counts.Triangles > 1000,
    "the surface has the planned counts (" + Num(e.Counts.Triangles) + " triangles)");
  Check(u.Extracted.Triangles == e.Counts.Triangles, "the update reports what it extracted");
  // Every point of a sphere of radius 12 about the centre lies within a voxel of it.
  bool onSphere = true;
  for (std::size_t p = 0; p + 2 < first->Points.size(); p += 3)
  {
    const double x = first->Points[p] - 0.5 * n + 0.3, y = first->Points[p + 1] - 0.5 * n + 0.1,
                 z = first->Points[p + 2] - 0.5 * n + 0.2;
    onSphere = onSphere && std::abs(std::sqrt(x * x + y * y + z * z) - 12.0) < 1.0;
  }
  Check(onSphere, "the surface's points lie on the sphere");
  Check(u.OneTimeWork && !unit.RecordCost(u, 0.01) && costs->GetNumberOfSamples() == 0,
    "the first update on a volume (block ranges) teaches the cost model nothing");

  // Again: a cache hit, no allocation, the same surface, no predicted seconds.
  Check(!unit.SetVolume(Describe(values, n, 1)), "the same description is not new");
  u = unit.Update({ 0.0 }, Fixed(3), maker.Make());
  Check(
    u.Status == Outcome::Done && u.Extractions == 0 && u.CacheHits == 1 && maker.Allocations == 1,
    "a cached pair is not extracted again (" + Num(maker.Allocations) + " allocations)");
  Check(unit.GetSurfaces().at(0) == first, "the cache returns the same surface");
  Check(unit.EstimateSeconds(0.0, 3) == 0.0, "a cached pair costs 0 s");
  Check(!unit.RecordCost(u, 0.001), "an update that extracted nothing is not recorded");

  // A new isovalue at the same level: recorded, and the model predicts from it.
  const double before = unit.EstimateSeconds(4.0, 3);
  u = unit.Update({ 0.0, 4.0 }, Fixed(3), maker.Make());
  Check(u.Extractions == 1 && u.CacheHits == 1 && !u.OneTimeWork, "one new pair, one cached");
  Check(unit.RecordCost(u, 0.5) && costs->GetNumberOfSamples() == 1,
    "the update's seconds reach the cost model");
  const double after = unit.EstimateSeconds(8.0, 3);
  Check(before > 0 && after > 10 * before,
    "the model predicts from the record (" + Num(before) + " s -> " + Num(after) + " s)");

  // A coarser level's first use makes its coarse copy: one-time work.
  u = unit.Update({ 0.0 }, Fixed(2), maker.Make());
  Check(u.Level == 2 && u.Extractions == 1 && u.OneTimeWork && !unit.RecordCost(u, 0.01) &&
      costs->GetNumberOfSamples() == 1,
    "a level's first coarse copy is one-time work, not recorded");

  // The cache limit: the least recently used pairs go, never the current ones.
  const double bytes3 = unit.GetCacheBytes();
  unit.SetCacheLimit(1.0);
  u = unit.Update({ 4.0 }, Fixed(2), maker.Make());
  Check(unit.GetCacheSize() == 1 && unit.IsCached({ 4.0, 2 }) && !unit.IsCached({ 0.0, 3 }),
    "over the limit only the current pair stays (" + Num(unit.GetCacheSize()) + " of " +
      Num(bytes3) + " bytes' pairs)");
  unit.SetCacheLimit(0);
  const int allocations = maker.Allocations;
  unit.Update({ 4.0 }, Fixed(1), maker.Make());
  unit.Update({ 4.0 }, Fixed(1), maker.Make());
  Check(maker.Allocations == allocations + 2 && !unit.IsCached({ 4.0, 1 }),
    "a limit of 0 caches nothing");

  // A new volume forgets the old one's surfaces.
  unit.SetCacheLimit(1e9);
  unit.Update({ 0.0 }, Fixed(3), maker.Make());
  Check(unit.IsCached({ 0.0, 3 }), "cached before the volume changes");
  Check(unit.SetVolume(Describe(values, n, 2)) && !unit.IsCached({ 0.0, 3 }) &&
      unit.GetCacheBytes() == 0,
    "a new stamp is a new volume, the cache emptied");
}

void TestAutoLevel()
{
  const int n = 40;
  const std::vector<float> values = Field(n, 12.0, 0.0);
  Surfaces unit(medical_test::FanCases.Cases, mediso::SerialFor, nullptr);
  unit.SetVolume(Describe(values, n, 1));
  Maker maker;
  double bytes[mediso::NumberOfLevels];
  for (int l = 0; l < mediso::NumberOfLevels; ++l)
  {
    bytes[l] = unit.EstimateBytes(0.0, l);
  }
  Check(bytes[0] > 0 && bytes[0] < bytes[1] && bytes[1] < bytes[2] && bytes[2] < bytes[3],
    "finer levels need more bytes");

  mediso::SurfacesUpdate u = unit.Update({ 0.0 }, Auto(bytes[3]), maker.Make());
  Check(u.Status == Outcome::Done && u.Level == 3, "a budget of level 3's bytes gives level 3");
  u = unit.Update({ 0.0 }, Auto(0.5 * (bytes[1] + bytes[2])), maker.Make());
  Check(u.Status == Outcome::Done && u.Level == 1 && u.Dropped.empty(),
    "a budget between levels 1 and 2 gives level 1 (" + Num(u.Level) + ")");

  // Below level 0: nothing (binding), or level 0 said to be over (guiding).
  const int allocations = maker.Allocations;
  u = unit.Update({ 0.0 }, Auto(0.5 * bytes[0]), maker.Make());
  Check(u.Status == Outcome::NothingFits && u.Level == -1 && unit.GetSurfaces().empty() &&
      maker.Allocations == allocations && std::abs(u.Level0Bytes - bytes[0]) < 1,
    "a binding budget below level 0 makes nothing and says level 0's bytes (" + Num(u.Level0Bytes) +
      ")");
  u = unit.Update({ 0.0 }, Auto(0.5 * bytes[0], false), maker.Make());
  Check(u.Status == Outcome::Done && u.Level == 0 && u.OverBudget && unit.GetSurfaces().size() == 1,
    "a guiding budget below level 0 makes level 0 and says it is over");
}

// An estimate below the exact bytes: the level is planned, found over the
// budget, and dropped for the next coarser one.
void TestRetryLower()
{
  // Noise gives blocks of uneven triangle counts, so that a sample of them
  // can miss some: an isovalue whose level-3 estimate is low is searched for.
  const int n = 96;
  const std::vector<float> values = Field(n, 30.0, 6.0);
  bool found = false;
  for (int i = 0; i < 40 && !found; ++i)
  {
    const double iso = -6.0 + 0.3 * i;
    Surfaces probe(medical_test::FanCases.Cases, mediso::SerialFor, nullptr);
    probe.SetSampleBudget(1.0); // the fewest samples: estimates, not counts
    probe.SetVolume(Describe(values, n, 1));
    const mediso::SurfaceEstimate e = probe.Estimate(iso, 3);
    const double estimated = probe.GetLayout().Bytes(e.Counts);
    const double level2 = probe.EstimateBytes(iso, 2);
    Maker maker;
    const mediso::SurfacesUpdate exact = probe.Update({ iso }, Fixed(3), maker.Make());
    const double exactBytes = probe.GetLayout().Bytes(
      mediso::SurfaceCounts{ static_cast<double>(probe.GetSurfaces().at(0)->Points.size() / 3),
        static_cast<double>(probe.GetSurfaces().at(0)->Triangles.size() / 3), 0 });
    const mediso::SurfacesUpdate coarser = probe.Update({ iso }, Fixed(2), maker.Make());
    const double exact2 = probe.GetLayout().Bytes(
      mediso::SurfaceCounts{ static_cast<double>(probe.GetSurfaces().at(0)->Points.size() / 3),
        static_cast<double>(probe.GetSurfaces().at(0)->Triangles.size() / 3), 0 });
    if (e.Method == mediso::EstimateMethod::Exact || exact.Status != Outcome::Done ||
      coarser.Status != Outcome::Done || !(estimated < exactBytes) || !(level2 < estimated) ||
      !(exact2 < estimated))
    {
      continue;
    }
    found = true;
    // A fresh unit with the same sampling: the same low estimate.
    Surfaces unit(medical_test::FanCases.Cases, mediso::SerialFor, nullptr);
    unit.SetSampleBudget(1.0);
    unit.SetVolume(Describe(values, n, 1));
    const double budget = 0.5 * (estimated + exactBytes);
    Maker counted;
    const mediso::SurfacesUpdate u = unit.Update({ iso }, Auto(budget), counted.Make());
    Check(u.Status == Outcome::Done && u.Level == 2,
      "isovalue " + Num(iso) + ": level 3 estimated at " + Num(estimated) + " bytes, exact " +
        Num(exactBytes) + ", budget " + Num(budget) + ": level 2 made (" + Num(u.Level) + ")");
    Check(u.Dropped.size() == 1 && u.Dropped[0].first == 3 &&
        std::abs(u.Dropped[0].second - exactBytes) < 1,
      "the dropped level and its exact bytes are reported");
    Check(counted.Allocations == 1, "only the level made is allocated");
    Check(unit.Estimate(iso, 3).Method == mediso::EstimateMethod::Exact,
      "the dropped level's plan made its estimate exact");
  }
  Check(found, "an isovalue with a low level-3 estimate was found");
}

void TestFailures()
{
  const int n = 40;
  const std::vector<float> values = Field(n, 12.0, 0.0);
  Surfaces unit(medical_test::FanCases.Cases, mediso::SerialFor, nullptr);
  unit.SetCacheLimit(1e9);
  unit.SetVolume(Describe(values, n, 1));

  Maker failing;
  failing.Fail = true;
  mediso::SurfacesUpdate u = unit.Update({ 0.0 }, Fixed(3), failing.Make());
  Check(u.Status == Outcome::OutOfMemory && u.Level == -1 && unit.GetSurfaces().empty() &&
      !unit.IsCached({ 0.0, 3 }),
    "a surface the host cannot allocate ends the update with nothing made");
  Check(u.Message.find("level 3's surface of isovalue 0 ran out of memory (") == 0,
    "the message names the surface: " + u.Message);

  Maker maker;
  mediso::UpdateHooks hooks;
  hooks.CheckAbort = []() { return true; };
  int planned = -1;
  hooks.Planned = [&planned](int level) { planned = level; };
  u = unit.Update({ 0.0, 4.0 }, Fixed(3), maker.Make(), hooks);
  Check(u.Status == Outcome::Aborted && u.Level == -1 && unit.GetSurfaces().empty() &&
      planned == -1 && maker.Allocations == 0,
    "an abort after the first plan stops before any surface");
}

// A host that recycles (SurfaceMaker::Recycle): the cache keeps the same pairs
// as without it (the same ones go, only earlier), and each dropped surface is
// offered once, before the allocation that needs its room.
void TestRecycle()
{
  const int n = 40;
  const std::vector<float> values = Field(n, 12.0, 0.5);
  Surfaces plain(medical_test::FanCases.Cases, mediso::SerialFor, nullptr);
  Surfaces recycling(medical_test::FanCases.Cases, mediso::SerialFor, nullptr);
  plain.SetVolume(Describe(values, n, 1));
  recycling.SetVolume(Describe(values, n, 1));
  Maker maker;
  std::vector<std::string> events; // "A" an allocation, "R" a surface offered
  std::vector<MeshRef> offered;
  mediso::SurfaceMaker<MeshRef> withRecycle = maker.Make();
  const auto allocate = withRecycle.Allocate;
  withRecycle.Allocate = [&](const mediso::SurfaceKey& key, std::int64_t points,
                           std::int64_t triangles, MeshRef& mesh, mediso::SurfaceTarget& target)
  {
    events.push_back("A");
    return allocate(key, points, triangles, mesh, target);
  };
  withRecycle.Recycle = [&](MeshRef& evicted)
  {
    events.push_back("R");
    offered.push_back(std::move(evicted)); // the host takes it
  };
  // A limit of about two and a half surfaces; updates of one and of two
  // isovalues.
  plain.SetCacheLimit(1e9);
  plain.Update({ 0.0 }, Fixed(3), maker.Make());
  const double limit = 2.5 * plain.GetCacheBytes();
  plain.ClearCache();
  plain.SetCacheLimit(limit);
  recycling.SetCacheLimit(limit);
  const std::vector<std::vector<double>> updates = { { 0.0 }, { 1.0 }, { 2.0 }, { 3.0, 4.0 },
    { 1.0, 5.0 }, { 6.0 }, { 5.0 }, { 7.0, 8.0 }, { 0.0 } };
  std::vector<double> all;
  bool same = true, offeredFirst = true;
  std::size_t dropped = 0;
  for (const std::vector<double>& isovalues : updates)
  {
    const std::size_t before = recycling.GetCacheSize();
    events.clear();
    const mediso::SurfacesUpdate a = plain.Update(isovalues, Fixed(3), maker.Make());
    const mediso::SurfacesUpdate b = recycling.Update(isovalues, Fixed(3), withRecycle);
    same = same && a.Status == Outcome::Done && b.Status == Outcome::Done &&
      a.Extractions == b.Extractions && a.CacheHits == b.CacheHits &&
      plain.GetCacheSize() == recycling.GetCacheSize() &&
      plain.GetCacheBytes() == recycling.GetCacheBytes();
    all.insert(all.end(), isovalues.begin(), isovalues.end());
    for (double v : all)
    {
      same = same && plain.IsCached({ v, 3 }) == recycling.IsCached({ v, 3 });
    }
    dropped += before + b.Extractions - recycling.GetCacheSize();
    // Offers only come just before an allocation.
    for (std::size_t e = 0; e < events.size(); ++e)
    {
      offeredFirst = offeredFirst && (events[e] == "A" || (e + 1 < events.size()));
    }
  }
  Check(same, "with Recycle the cache holds the same pairs after every update");
  Check(dropped > 0 && offered.size() == dropped,
    "every dropped surface is offered once (" + Num(offered.size()) + " of " + Num(dropped) + ")");
  bool whole = true;
  for (const MeshRef& mesh : offered)
  {
    whole = whole && mesh && !mesh->Triangles.empty();
  }
  Check(whole && offeredFirst, "the offered surfaces are whole, offered before an allocation");

  // No room needed, nothing offered.
  const std::size_t offers = offered.size();
  recycling.SetCacheLimit(1e9);
  recycling.Update({ 9.0 }, Fixed(3), withRecycle);
  Check(offered.size() == offers, "a cache with room offers nothing");
}
} // namespace

int main()
{
  TestFixedLevelAndCache();
  TestAutoLevel();
  TestRetryLower();
  TestFailures();
  TestRecycle();
  return medical_test::Finish("TestBlockLODSurfacesCore passed");
}
