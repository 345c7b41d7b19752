// SPDX-License-Identifier: BSD-3-Clause
// Unit test of the extraction ahead of BlockLODVolume's streaming
// (Filters/Core/BlockLODVolume.h: SetAheadIsovalues, TakeAhead) and its use by
// the surfaces unit (BlockLODSurfaces.h: SurfaceMaker::Adopt), on the noisy
// sphere of StreamingTestField.h arriving brick by brick:
// - taken at several stages once an isovalue's needed bricks are resident
//   (the first such stage, one between, the last brick, after the end), the
//   surface made ahead is the dense volume's level-3 surface exactly: the
//   same numbers of points and triangles, and the same triangles (each
//   vertex's point and normal, bit for bit), only in another order;
// - taken before then, it is what Plan() and Generate() make of the resident
//   blocks at that moment;
// - an isovalue named mid-stream catches up over the blocks already there;
//   one no longer named is forgotten; a taken surface is no longer held;
// - the surfaces unit, at level 3, takes the surface made ahead (no
//   extraction) and gives the dense surface; a maker without Adopt, or an
//   isovalue not named, extracts it as before.
#include "BlockLODSurfaces.h"
#include "BlockLODVolume.h"
#include "FanCaseTable.h"
#include "MedicalTestUtilities.h"
#include "StreamingTestField.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using medical_test::StreamingField;
using medical_test::ExtractFullLevel;

constexpr int FullLevel = mediso::NumberOfLevels - 1;


// A surface whatever the order of its points and triangles: each triangle as
// its three vertices (point and normal), turned to begin with its smallest
// vertex (its orientation kept), the triangles sorted.
using Vertex = std::array<float, 6>;
using Triangle = std::array<Vertex, 3>;
std::vector<Triangle> Canonical(const mediso::SurfaceArrays& mesh)
{
  std::vector<Triangle> triangles(mesh.Triangles.size() / 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    Triangle tri;
    for (int c = 0; c < 3; ++c)
    {
      const std::size_t p = static_cast<std::size_t>(mesh.Triangles[3 * t + c]);
      for (int k = 0; k < 3; ++k)
      {
        tri[c][k] = mesh.Points[3 * p + k];
        tri[c][3 + k] = mesh.Normals[3 * p + k];
      }
    }
    const int first = static_cast<int>(std::min_element(tri.begin(), tri.end()) - tri.begin());
    std::rotate(tri.begin(), tri.begin() + first, tri.end());
    triangles[t] = tri;
  }
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

// Every point is used by a triangle (the surface holds no stray point).
bool EveryPointUsed(const mediso::SurfaceArrays& mesh)
{
  std::vector<char> used(mesh.Points.size() / 3, 0);
  for (std::int32_t id : mesh.Triangles)
  {
    if (id < 0 || static_cast<std::size_t>(id) >= used.size())
    {
      return false;
    }
    used[static_cast<std::size_t>(id)] = 1;
  }
  return std::all_of(used.begin(), used.end(), [](char u) { return u != 0; });
}

void CheckSame(
  const mediso::SurfaceArrays& got, const mediso::SurfaceArrays& expected, const std::string& what)
{
  Check(got.Points.size() == expected.Points.size() && got.Normals.size() == got.Points.size(),
    what + ": the points' count (" + std::to_string(got.Points.size() / 3) + " against " +
      std::to_string(expected.Points.size() / 3) + ")");
  Check(got.Triangles.size() == expected.Triangles.size(),
    what + ": the triangles' count (" + std::to_string(got.Triangles.size() / 3) + " against " +
      std::to_string(expected.Triangles.size() / 3) + ")");
  Check(Canonical(got) == Canonical(expected), what + ": the same triangles, points and normals");
  Check(EveryPointUsed(got), what + ": every point used");
}

// The first stage (bricks arrived) at which every brick an isovalue needs is resident.
int ReadyStage(const StreamingField& field, double v)
{
  const std::vector<char> need = field.Needed(v);
  std::vector<char> resident(field.Count(), 0);
  for (int n = 0; n < field.Count(); ++n)
  {
    resident[field.Arriving(n)] = 1;
    bool ready = true;
    for (int i = 0; i < field.Count(); ++i)
    {
      ready = ready && (!need[i] || resident[i]);
    }
    if (ready)
    {
      return n + 1;
    }
  }
  return field.Count();
}

// The surfaces unit's surface: plain arrays, adopted or allocated.
using Surface = std::shared_ptr<mediso::SurfaceArrays>;
mediso::SurfaceMaker<Surface> Maker(bool adopt)
{
  mediso::SurfaceMaker<Surface> maker;
  maker.Allocate = [](const mediso::SurfaceKey&, std::int64_t points, std::int64_t triangles,
                     Surface& surface, mediso::SurfaceTarget& target)
  {
    surface = std::make_shared<mediso::SurfaceArrays>();
    surface->Points.resize(3 * static_cast<std::size_t>(points));
    surface->Normals.resize(surface->Points.size());
    surface->Triangles.resize(3 * static_cast<std::size_t>(triangles));
    target.Narrow.Points = surface->Points.data();
    target.Narrow.Normals = surface->Normals.data();
    target.Narrow.Connectivity = surface->Triangles.data();
    return true;
  };
  if (adopt)
  {
    maker.Adopt = [](const mediso::SurfaceKey&, mediso::SurfaceArrays& arrays, Surface& surface)
    {
      surface = std::make_shared<mediso::SurfaceArrays>(std::move(arrays));
      return true;
    };
  }
  return maker;
}
} // namespace

int main()
{
  const StreamingField field;
  const int count = field.Count();
  const double isovalues[3] = { 650.0, 1400.0, 1000.0 };
  mediso::BlockLODVolume dense(medical_test::FanCases.Cases, mediso::SerialFor);
  dense.SetVolume(field.Describe(field.Values.data()));
  std::vector<mediso::SurfaceArrays> expected;
  for (double v : isovalues)
  {
    expected.push_back(ExtractFullLevel(dense, v));
    Check(!expected.back().Triangles.empty(),
      "the dense surface at " + std::to_string(v) + " has triangles");
  }

  // Streams the first `stages` bricks: the first two isovalues named from the
  // start, the third after `third` bricks (never when negative).
  auto stream =
    [&](mediso::BlockLODVolume& volume, std::vector<std::int16_t>& buffer, int stages, int third)
  {
    buffer.assign(field.Values.size(), 30000);
    volume.SetVolume(field.Describe(buffer.data()));
    volume.BeginStreaming();
    volume.SetAheadIsovalues({ isovalues[0], isovalues[1] });
    for (int n = 0; n < stages; ++n)
    {
      if (n == third)
      {
        volume.SetAheadIsovalues({ isovalues[0], isovalues[1], isovalues[2] });
      }
      field.Arrive(field.Arriving(n), buffer, volume);
    }
  };

  // Taken at several stages of each isovalue: before it is ready (what Plan
  // and Generate see then), when it becomes ready, between, at the last brick.
  int readyChecked = 0;
  for (int s = 0; s < 3; ++s)
  {
    const int ready = ReadyStage(field, isovalues[s]);
    Check(ready < count,
      "isovalue " + std::to_string(isovalues[s]) + " is ready before the last brick");
    const int third = count / 3; // the third isovalue is named here (before it is ready)
    Check(s < 2 || third < ready, "the third isovalue is named before it is ready");
    for (int stages : { std::max(third + 1, ready / 2), ready, (ready + count) / 2, count })
    {
      mediso::BlockLODVolume volume(medical_test::FanCases.Cases, mediso::SerialFor);
      std::vector<std::int16_t> buffer;
      stream(volume, buffer, stages, third);
      const std::string what = "isovalue " + std::to_string(isovalues[s]) + " taken after " +
        std::to_string(stages) + " of " + std::to_string(count) + " bricks";
      mediso::SurfaceArrays got;
      Check(volume.TakeAhead(isovalues[s], got), what + ": made ahead");
      if (stages >= ready)
      {
        CheckSame(got, expected[s], what + " (ready)");
        ++readyChecked;
      }
      else
      {
        CheckSame(got, ExtractFullLevel(volume, isovalues[s]), what + " (not ready: the resident blocks')");
      }
      mediso::SurfaceArrays again;
      Check(!volume.TakeAhead(isovalues[s], again), what + ": no longer held once taken");
    }
  }
  Check(readyChecked == 9, "three ready stages of each isovalue checked");

  // Named, then no longer: forgotten. After the end, a surface made ahead is kept until taken.
  {
    mediso::BlockLODVolume volume(medical_test::FanCases.Cases, mediso::SerialFor);
    std::vector<std::int16_t> buffer;
    stream(volume, buffer, count / 2, -1);
    volume.SetAheadIsovalues({ isovalues[1] });
    Check(volume.GetAheadIsovalues() == std::vector<double>{ isovalues[1] },
      "an isovalue no longer named is forgotten");
    mediso::SurfaceArrays got;
    Check(!volume.TakeAhead(isovalues[0], got), "a forgotten isovalue has nothing ahead");
    for (int n = count / 2; n < count; ++n)
    {
      field.Arrive(field.Arriving(n), buffer, volume);
    }
    volume.EndStreaming();
    Check(volume.TakeAhead(isovalues[1], got), "after the end, the surface made ahead is kept");
    CheckSame(got, expected[1], "taken after the end");
    volume.SetAheadIsovalues({ isovalues[0] });
    Check(volume.GetAheadIsovalues().empty(), "not streaming, naming an isovalue starts nothing");
  }

  // Not streaming, or never named: nothing ahead.
  {
    mediso::SurfaceArrays got;
    dense.SetAheadIsovalues({ isovalues[0] });
    Check(!dense.TakeAhead(isovalues[0], got), "a volume that does not stream makes nothing ahead");
  }

  // The surfaces unit: at level 3 it takes the surface made ahead (with Adopt), else extracts.
  for (bool adopt : { true, false })
  {
    mediso::BlockLODSurfaces<Surface> unit(
      medical_test::FanCases.Cases, mediso::SerialFor, nullptr);
    unit.SetCacheLimit(1e9);
    std::vector<std::int16_t> buffer(field.Values.size(), 30000);
    unit.SetVolume(field.Describe(buffer.data()));
    unit.BeginStreaming();
    unit.SetAheadIsovalues({ isovalues[0] });
    for (int n = 0; n < count; ++n)
    {
      field.Arrive(field.Arriving(n), buffer, unit);
    }
    mediso::LevelChoice choice;
    choice.Level = FullLevel;
    const mediso::SurfacesUpdate update =
      unit.Update({ isovalues[0], isovalues[1] }, choice, Maker(adopt));
    const std::string what = adopt ? "the unit, with Adopt" : "the unit, without Adopt";
    Check(update.Status == mediso::SurfacesUpdate::Outcome::Done, what + ": done");
    Check(update.TakenAhead == (adopt ? 1 : 0) && update.Extractions == (adopt ? 1 : 2),
      what + ": the named isovalue taken ahead, the other extracted (" +
        std::to_string(update.TakenAhead) + " taken, " + std::to_string(update.Extractions) +
        " extracted)");
    Check(unit.GetSurfaces().size() == 2, what + ": two surfaces");
    CheckSame(*unit.GetSurfaces()[0], expected[0], what + ", isovalue 650");
    CheckSame(*unit.GetSurfaces()[1], expected[1], what + ", isovalue 1400");
    unit.SetAheadIsovalues({ isovalues[0] });
    Check(unit.GetVolume().GetAheadIsovalues().empty(),
      what + ": an isovalue cached at level 3 is not made ahead again");
  }
  return medical_test::Finish("TestBlockLODVolumeStreamingAheadCore");
}
