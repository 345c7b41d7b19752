// SPDX-License-Identifier: BSD-3-Clause
// What the streaming core tests (TestBlockLODVolumeStreamingCore,
// TestBlockLODVolumeStreamingAheadCore) share: a noisy sphere whose dimensions
// are not multiples of the block size, its bricks, each brick's value range as
// the server's manifest states it, and the bricks an isovalue needs (those
// whose range holds it, and their 26 neighbours), with the order the bricks
// arrive in (a stride through the ids, not the volume's order).
#ifndef MedicalIsosurfaces_StreamingTestField_h
#define MedicalIsosurfaces_StreamingTestField_h

#include "BlockLODVolume.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace medical_test
{
struct StreamingField
{
  static constexpr int Brick = 16; // points a side, a multiple of mediso::BlockCells

  int Dims[3] = { 77, 70, 45 };
  std::vector<std::int16_t> Values;
  int Bricks[3] = { 0, 0, 0 };
  std::vector<double> Lo, Hi; // each brick's range over its points with an apron of 1

  StreamingField()
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
    for (int a = 0; a < 3; ++a)
    {
      this->Bricks[a] = (this->Dims[a] + Brick - 1) / Brick;
    }
    this->Lo.assign(this->Count(), 1e30);
    this->Hi.assign(this->Count(), -1e30);
    for (int id = 0; id < this->Count(); ++id)
    {
      int b[3], first[3], last[3];
      this->Coords(id, b);
      this->BrickBox(b, 1, first, last);
      for (int k = first[2]; k <= last[2]; ++k)
        for (int j = first[1]; j <= last[1]; ++j)
          for (int i = first[0]; i <= last[0]; ++i)
          {
            this->Lo[id] = std::min<double>(this->Lo[id], this->Values[this->Index(i, j, k)]);
            this->Hi[id] = std::max<double>(this->Hi[id], this->Values[this->Index(i, j, k)]);
          }
    }
  }
  std::size_t Index(int i, int j, int k) const
  {
    return (static_cast<std::size_t>(k) * this->Dims[1] + j) * this->Dims[0] + i;
  }
  int Count() const { return this->Bricks[0] * this->Bricks[1] * this->Bricks[2]; }
  void Coords(int id, int b[3]) const
  {
    b[0] = id % this->Bricks[0];
    b[1] = (id / this->Bricks[0]) % this->Bricks[1];
    b[2] = id / (this->Bricks[0] * this->Bricks[1]);
  }
  // A brick's first and last point along each axis, with `apron` more on each
  // side and one more on the + side (what its cells and gradients read).
  void BrickBox(const int b[3], int apron, int first[3], int last[3]) const
  {
    for (int a = 0; a < 3; ++a)
    {
      first[a] = std::max(0, b[a] * Brick - apron);
      last[a] = std::min(this->Dims[a] - 1, (b[a] + 1) * Brick + apron);
    }
  }
  // The brick that arrives n-th.
  int Arriving(int n) const { return (n * 7) % this->Count(); }
  // Writes the brick `id`'s own points into `buffer` and tells `volume` (a
  // BlockLODVolume or a surfaces unit: anything with RegionArrived).
  template <typename Streamed>
  void Arrive(int id, std::vector<std::int16_t>& buffer, Streamed& volume) const
  {
    int b[3], first[3], last[3];
    this->Coords(id, b);
    this->BrickBox(b, 0, first, last);
    for (int a = 0; a < 3; ++a)
    {
      last[a] = std::min(this->Dims[a] - 1, (b[a] + 1) * Brick - 1);
    }
    for (int k = first[2]; k <= last[2]; ++k)
      for (int j = first[1]; j <= last[1]; ++j)
        for (int i = first[0]; i <= last[0]; ++i)
        {
          buffer[this->Index(i, j, k)] = this->Values[this->Index(i, j, k)];
        }
    volume.RegionArrived(first, last);
  }
  // The bricks an isovalue needs: the active ones and their 26 neighbours.
  std::vector<char> Needed(double v) const
  {
    std::vector<char> need(this->Count(), 0);
    for (int id = 0; id < this->Count(); ++id)
    {
      if (!(this->Lo[id] < v && v <= this->Hi[id]))
      {
        continue;
      }
      int b[3];
      this->Coords(id, b);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
          {
            const int n[3] = { b[0] + dx, b[1] + dy, b[2] + dz };
            if (n[0] >= 0 && n[1] >= 0 && n[2] >= 0 && n[0] < this->Bricks[0] &&
              n[1] < this->Bricks[1] && n[2] < this->Bricks[2])
            {
              need[(n[2] * this->Bricks[1] + n[1]) * this->Bricks[0] + n[0]] = 1;
            }
          }
    }
    return need;
  }
  mediso::VolumeDescription Describe(const std::int16_t* data) const
  {
    mediso::VolumeDescription d;
    d.Type = mediso::ScalarType::Int16;
    d.Data = data;
    std::copy(this->Dims, this->Dims + 3, d.Dims);
    return d;
  }
};
/// A volume's full-level surface of `isovalue`, as the dense filter extracts it (Plan, then
/// Generate into arrays sized by the plan).
inline mediso::SurfaceArrays ExtractFullLevel(mediso::BlockLODVolume& volume, double isovalue)
{
  mediso::ExtractionPlan plan;
  volume.Plan(isovalue, mediso::NumberOfLevels - 1, plan);
  mediso::SurfaceArrays mesh;
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
} // namespace medical_test

#endif
