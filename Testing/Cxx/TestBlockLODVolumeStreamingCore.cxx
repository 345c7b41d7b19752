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
//   given when not streaming, completes nothing.
#include "BlockLODVolume.h"
#include "FanCaseTable.h"
#include "MedicalTestUtilities.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

constexpr int Brick = 16; // points a side, a multiple of mediso::BlockCells

struct Field
{
  int Dims[3] = { 77, 70, 45 };
  std::vector<std::int16_t> Values;
  Field()
  {
    this->Values.resize(static_cast<std::size_t>(this->Dims[0]) * this->Dims[1] * this->Dims[2]);
    std::uint32_t state = 2463534242u;
    std::size_t id = 0;
    for (int k = 0; k < this->Dims[2]; ++k)
      for (int j = 0; j < this->Dims[1]; ++j)
        for (int i = 0; i < this->Dims[0]; ++i, ++id)
        {
          state ^= state << 13;
          state ^= state >> 17;
          state ^= state << 5;
          const double r =
            std::sqrt((i - 20.0) * (i - 20.0) + (j - 17.0) * (j - 17.0) + (k - 12.0) * (k - 12.0));
          this->Values[id] = static_cast<std::int16_t>(100.0 * r + (state % 60));
        }
  }
  std::size_t Index(int i, int j, int k) const
  {
    return (static_cast<std::size_t>(k) * this->Dims[1] + j) * this->Dims[0] + i;
  }
};

mediso::VolumeDescription Describe(const Field& f, const std::int16_t* data)
{
  mediso::VolumeDescription d;
  d.Type = mediso::ScalarType::Int16;
  d.Data = data;
  std::copy(f.Dims, f.Dims + 3, d.Dims);
  return d;
}

struct Mesh
{
  std::vector<float> Points, Normals;
  std::vector<std::int32_t> Triangles;
};

Mesh Extract(mediso::BlockLODVolume& volume, double isovalue)
{
  mediso::ExtractionPlan plan;
  volume.Plan(isovalue, mediso::NumberOfLevels - 1, plan);
  Mesh mesh;
  mesh.Points.resize(3 * plan.GetNumberOfPoints());
  mesh.Normals.resize(mesh.Points.size());
  mesh.Triangles.resize(3 * plan.GetNumberOfTriangles());
  mediso::SurfaceBuffers<std::int32_t> out;
  out.Points = mesh.Points.data();
  out.Normals = mesh.Normals.data();
  out.Connectivity = mesh.Triangles.data();
  volume.Generate(plan, out);
  return mesh;
}

// A brick's first and last point along each axis, with `apron` more on each
// side and one more on the + side (what its cells and gradients read).
void BrickBox(const Field& f, const int b[3], int apron, int first[3], int last[3])
{
  for (int a = 0; a < 3; ++a)
  {
    first[a] = std::max(0, b[a] * Brick - apron);
    last[a] = std::min(f.Dims[a] - 1, (b[a] + 1) * Brick + apron);
  }
}
} // namespace

int main()
{
  const Field field;
  const double isovalues[2] = { 650.0, 1400.0 };
  mediso::BlockLODVolume dense(medical_test::FanCases.Cases, mediso::SerialFor);
  dense.SetVolume(Describe(field, field.Values.data()));
  std::vector<Mesh> expected;
  for (double v : isovalues)
  {
    expected.push_back(Extract(dense, v));
    Check(!expected.back().Triangles.empty(),
      "the dense surface at " + std::to_string(v) + " has triangles");
  }

  // The streaming buffer starts with a value every isovalue cuts against the
  // arrived ones.
  std::vector<std::int16_t> buffer(field.Values.size(), 30000);
  mediso::BlockLODVolume streamed(medical_test::FanCases.Cases, mediso::SerialFor);
  streamed.SetVolume(Describe(field, buffer.data()));
  const int nowhere[3] = { 0, 0, 0 };
  Check(streamed.RegionArrived(nowhere, nowhere) == 0,
    "a region given when not streaming completes nothing");
  streamed.BeginStreaming();
  Check(streamed.IsStreaming() && streamed.GetNumberOfResidentBlocks() == 0,
    "streaming, nothing resident");
  for (double v : isovalues)
  {
    Check(Extract(streamed, v).Triangles.empty(), "no triangle before any brick");
  }
  const int outsideFirst[3] = { 100, 0, 0 }, outsideLast[3] = { 120, 5, 5 };
  Check(streamed.RegionArrived(outsideFirst, outsideLast) == 0,
    "a region outside the volume completes nothing");

  int bricks[3];
  for (int a = 0; a < 3; ++a)
  {
    bricks[a] = (field.Dims[a] + Brick - 1) / Brick;
  }
  const int count = bricks[0] * bricks[1] * bricks[2];
  auto coords = [&](int id, int b[3]) {
    b[0] = id % bricks[0];
    b[1] = (id / bricks[0]) % bricks[1];
    b[2] = id / (bricks[0] * bricks[1]);
  };
  // Each brick's range over its points with an apron of 1 (what the server's
  // manifest states).
  std::vector<double> lo(count), hi(count);
  for (int id = 0; id < count; ++id)
  {
    int b[3], first[3], last[3];
    coords(id, b);
    BrickBox(field, b, 1, first, last);
    lo[id] = 1e30;
    hi[id] = -1e30;
    for (int k = first[2]; k <= last[2]; ++k)
      for (int j = first[1]; j <= last[1]; ++j)
        for (int i = first[0]; i <= last[0]; ++i)
        {
          lo[id] = std::min<double>(lo[id], field.Values[field.Index(i, j, k)]);
          hi[id] = std::max<double>(hi[id], field.Values[field.Index(i, j, k)]);
        }
  }
  // The bricks an isovalue needs: the active ones and their 26 neighbours.
  auto needed = [&](double v) {
    std::vector<char> need(count, 0);
    for (int id = 0; id < count; ++id)
    {
      if (!(lo[id] < v && v <= hi[id]))
      {
        continue;
      }
      int b[3];
      coords(id, b);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
          {
            const int n[3] = { b[0] + dx, b[1] + dy, b[2] + dz };
            if (n[0] >= 0 && n[1] >= 0 && n[2] >= 0 && n[0] < bricks[0] && n[1] < bricks[1] &&
              n[2] < bricks[2])
            {
              need[(n[2] * bricks[1] + n[1]) * bricks[0] + n[0]] = 1;
            }
          }
    }
    return need;
  };
  const std::vector<char> needs[2] = { needed(isovalues[0]), needed(isovalues[1]) };

  // The bricks arrive in an order that is not the volume's (a stride through
  // the ids).
  std::vector<char> resident(count, 0);
  int exactStages[2] = { 0, 0 };
  for (int n = 0; n < count; ++n)
  {
    const int id = (n * 7) % count;
    int b[3], first[3], last[3];
    coords(id, b);
    BrickBox(field, b, 0, first, last);
    last[0] = std::min(field.Dims[0] - 1, (b[0] + 1) * Brick - 1);
    last[1] = std::min(field.Dims[1] - 1, (b[1] + 1) * Brick - 1);
    last[2] = std::min(field.Dims[2] - 1, (b[2] + 1) * Brick - 1);
    for (int k = first[2]; k <= last[2]; ++k)
      for (int j = first[1]; j <= last[1]; ++j)
        for (int i = first[0]; i <= last[0]; ++i)
        {
          buffer[field.Index(i, j, k)] = field.Values[field.Index(i, j, k)];
        }
    streamed.RegionArrived(first, last);
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
      const Mesh got = Extract(streamed, isovalues[s]);
      const std::string stage = "after " + std::to_string(n + 1) + " of " + std::to_string(count) +
        " bricks, isovalue " + std::to_string(isovalues[s]);
      Check(got.Triangles == expected[s].Triangles, stage + ": the dense surface's triangles");
      Check(got.Points == expected[s].Points, stage + ": the dense surface's points");
      Check(got.Normals == expected[s].Normals, stage + ": the dense surface's normals");
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
  streamed.EndStreaming();
  Check(!streamed.IsStreaming(), "streaming ended");
  for (int s = 0; s < 2; ++s)
  {
    const Mesh got = Extract(streamed, isovalues[s]);
    Check(got.Triangles == expected[s].Triangles && got.Points == expected[s].Points,
      "after the end, the dense surface");
  }
  return medical_test::Finish("TestBlockLODVolumeStreamingCore");
}
