// SPDX-License-Identifier: BSD-3-Clause
// Unit test of BlockLODVolume's streaming (Filters/Core/BlockLODVolume.h): a
// volume whose values arrive brick by brick, as the web page fetches them, on a
// noisy sphere whose dimensions are not multiples of the block size, with the
// tests' own case table (FanCaseTable.h):
// - before any brick, no block is visited, whatever the buffer holds (here a
//   value that every isovalue would cut against the arrived ones);
// - after each brick, an isovalue whose needed bricks are all resident (those
//   whose points, with one more on each side, hold it between their minimum
//   and maximum, and their neighbours) has the dense volume's level-3 surface
//   exactly: the same triangles, points and normals;
// - once every brick arrived, the ranges are the dense volume's, block for
//   block, with the value range; a region outside the volume, or a region
//   given when not streaming, completes nothing;
// - a volume adopted streaming from the start (SetStreamingVolume: no ranges
//   read from the buffer) starts as SetVolume then BeginStreaming leave it,
//   every block's range empty whatever the buffer holds, and gives the same
//   surfaces at every stage and the same ranges at the end.
#include "BlockLODVolume.h"
#include "FanCaseTable.h"
#include "MedicalTestUtilities.h"
#include "StreamingTestField.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using medical_test::StreamingField;

using Mesh = mediso::SurfaceArrays;
using medical_test::ExtractFullLevel;
} // namespace

int main()
{
  const StreamingField field;
  const double isovalues[2] = { 650.0, 1400.0 };
  mediso::BlockLODVolume dense(medical_test::FanCases.Cases, mediso::SerialFor);
  dense.SetVolume(field.Describe(field.Values.data()));
  std::vector<Mesh> expected;
  for (double v : isovalues)
  {
    expected.push_back(ExtractFullLevel(dense, v));
    Check(!expected.back().Triangles.empty(),
      "the dense surface at " + std::to_string(v) + " has triangles");
  }

  // The streaming buffer starts with a value every isovalue cuts against the
  // arrived ones.
  std::vector<std::int16_t> buffer(field.Values.size(), 30000);
  mediso::BlockLODVolume streamed(medical_test::FanCases.Cases, mediso::SerialFor);
  streamed.SetVolume(field.Describe(buffer.data()));
  const int nowhere[3] = { 0, 0, 0 };
  Check(streamed.RegionArrived(nowhere, nowhere) == 0,
    "a region given when not streaming completes nothing");
  streamed.BeginStreaming();
  Check(streamed.IsStreaming() && streamed.GetNumberOfResidentBlocks() == 0,
    "streaming, nothing resident");
  std::vector<std::int16_t> atOnceBuffer(field.Values.size(), 30000);
  mediso::BlockLODVolume atOnce(medical_test::FanCases.Cases, mediso::SerialFor);
  Check(atOnce.SetStreamingVolume(field.Describe(atOnceBuffer.data())) && atOnce.IsValid() &&
      atOnce.IsStreaming() && atOnce.GetNumberOfResidentBlocks() == 0,
    "adopted streaming from the start: valid, streaming, nothing resident");
  {
    const mediso::BlockRanges& r = atOnce.GetRanges();
    const mediso::BlockRanges& s = streamed.GetRanges();
    Check(r.GetNumberOfBlocks() == dense.GetRanges().GetNumberOfBlocks() && r.Min == s.Min &&
        r.Max == s.Max &&
        std::all_of(r.Min.begin(), r.Min.end(), [](double m) { return std::isinf(m) && m > 0; }) &&
        !r.HasFiniteValues(),
      "... its ranges sized and empty, as SetVolume then BeginStreaming leave them");
  }
  for (double v : isovalues)
  {
    Check(ExtractFullLevel(streamed, v).Triangles.empty(), "no triangle before any brick");
  }
  const int outsideFirst[3] = { 100, 0, 0 }, outsideLast[3] = { 120, 5, 5 };
  Check(streamed.RegionArrived(outsideFirst, outsideLast) == 0,
    "a region outside the volume completes nothing");

  const int count = field.Count();
  const std::vector<char> needs[2] = { field.Needed(isovalues[0]), field.Needed(isovalues[1]) };

  // The bricks arrive in an order that is not the volume's (a stride through
  // the ids).
  std::vector<char> resident(count, 0);
  int exactStages[2] = { 0, 0 };
  for (int n = 0; n < count; ++n)
  {
    const int id = field.Arriving(n);
    field.Arrive(id, buffer, streamed);
    field.Arrive(id, atOnceBuffer, atOnce);
    resident[id] = 1;
    for (int s = 0; s < 2; ++s)
    {
      bool ready = true;
      for (int i = 0; i < count; ++i)
      {
        ready = ready && (!needs[s][i] || resident[i]);
      }
      if (!ready)
      {
        continue;
      }
      const Mesh got = ExtractFullLevel(streamed, isovalues[s]);
      const std::string stage = "after " + std::to_string(n + 1) + " of " + std::to_string(count) +
        " bricks, isovalue " + std::to_string(isovalues[s]);
      Check(got.Triangles == expected[s].Triangles, stage + ": the dense surface's triangles");
      Check(got.Points == expected[s].Points, stage + ": the dense surface's points");
      Check(got.Normals == expected[s].Normals, stage + ": the dense surface's normals");
      const Mesh gotAtOnce = ExtractFullLevel(atOnce, isovalues[s]);
      Check(gotAtOnce.Triangles == expected[s].Triangles &&
          gotAtOnce.Points == expected[s].Points && gotAtOnce.Normals == expected[s].Normals,
        stage + ", streaming from the start: the dense surface");
      ++exactStages[s];
    }
  }
  Check(exactStages[0] > 1 && exactStages[1] > 1,
    "each surface is complete before the last brick (" + std::to_string(exactStages[0]) + ", " +
      std::to_string(exactStages[1]) + " stages)");
  Check(streamed.GetNumberOfResidentBlocks() == dense.GetRanges().GetNumberOfBlocks(),
    "every block resident at the end");
  const mediso::BlockRanges& a = streamed.GetRanges();
  const mediso::BlockRanges& d = dense.GetRanges();
  Check(a.Min == d.Min && a.Max == d.Max, "the ranges are the dense volume's at the end");
  Check(a.ValueRange[0] == d.ValueRange[0] && a.ValueRange[1] == d.ValueRange[1],
    "the value range is the dense volume's at the end");
  const mediso::BlockRanges& o = atOnce.GetRanges();
  Check(atOnce.GetNumberOfResidentBlocks() == d.GetNumberOfBlocks() && o.Min == d.Min &&
      o.Max == d.Max && o.ValueRange[0] == d.ValueRange[0] && o.ValueRange[1] == d.ValueRange[1],
    "streaming from the start: every block resident and the dense ranges at the end");
  streamed.EndStreaming();
  Check(!streamed.IsStreaming(), "streaming ended");
  for (int s = 0; s < 2; ++s)
  {
    const Mesh got = ExtractFullLevel(streamed, isovalues[s]);
    Check(got.Triangles == expected[s].Triangles && got.Points == expected[s].Points,
      "after the end, the dense surface");
  }
  return medical_test::Finish("TestBlockLODVolumeStreamingCore");
}
