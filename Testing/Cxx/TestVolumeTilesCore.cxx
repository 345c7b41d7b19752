// SPDX-License-Identifier: BSD-3-Clause
// Unit test of the GPU pyramid's CPU-side volume work (Mappers/Core/VolumeTiles),
// without VTK or OpenGL:
//  - PackVolumeRows() keeps every value and pads each row with its last point;
//    PackVolumeBox() packs a box of a volume as its copy would be packed, and
//    the tiles of packed rows (Compute() with their row length) are the values';
//  - a level-1 tile is active for a set of isovalues exactly when one of its
//    cells crosses one (a superset where the volume has NaN values, whose
//    cells cross nothing), for several scalar types and shapes that fill no
//    whole tile;
//  - ActiveRectangles() covers exactly the active tiles' texels, and hands a
//    host's parallel for one task for a brick's tiles (no thread started per
//    brick at each isovalue change) and tasks of at least MinimumTilesPerTask
//    tiles for a large volume, with the serial scan's rectangles; Compute()
//    and PackVolumeBox() hand it tasks of at least MinimumPointsPerTask
//    points (one for a brick of 56 points), with the serial results.
#include "MedicalTestUtilities.h"

#include "IsoThresholds.h"
#include "PyramidLayout.h"
#include "VolumeTiles.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace
{
using medical_test::Check;
using mediso::PyramidLayout;

std::string Shape(const int points[3])
{
  return std::to_string(points[0]) + "x" + std::to_string(points[1]) + "x" +
    std::to_string(points[2]);
}

template<typename T>
void CheckPacking(const std::vector<T>& values, const int points[3])
{
  const int width = mediso::PackedVolumeWidth(points[0]);
  const std::vector<unsigned char> packed =
    mediso::PackVolumeRows(values.data(), points, static_cast<int>(sizeof(T)), {});
  const std::size_t rows = static_cast<std::size_t>(points[1]) * points[2];
  bool ok = packed.size() == 4 * static_cast<std::size_t>(width) * rows * sizeof(T);
  for (std::size_t r = 0; ok && r < rows; ++r)
  {
    for (int x = 0; x < 4 * width; ++x)
    {
      T got;
      std::memcpy(&got, packed.data() + (4 * width * r + x) * sizeof(T), sizeof(T));
      const T expected = values[r * points[0] + std::min(x, points[0] - 1)];
      ok = ok && std::memcmp(&got, &expected, sizeof(T)) == 0;
    }
  }
  Check(ok, Shape(points) + ": packed rows keep every value and repeat a row's last point");

  // A box of the volume (a brick with its apron) packed in one copy is the
  // box copied out and packed; the tiles of the packed rows are those of the box.
  const int extent[6] = { points[0] / 3, points[0] - 1, 0, points[1] / 2, points[2] > 2 ? 1 : 0,
    points[2] - 1 };
  const int boxPoints[3] = { extent[1] - extent[0] + 1, extent[3] - extent[2] + 1,
    extent[5] - extent[4] + 1 };
  std::vector<T> box;
  for (int z = extent[4]; z <= extent[5]; ++z)
    for (int y = extent[2]; y <= extent[3]; ++y)
      for (int x = extent[0]; x <= extent[1]; ++x)
      {
        box.push_back(values[(static_cast<std::size_t>(z) * points[1] + y) * points[0] + x]);
      }
  std::vector<unsigned char> boxPacked(3, 0xff); // storage there is reused, not appended to
  mediso::PackVolumeBox(values.data(), points, extent, static_cast<int>(sizeof(T)),
    [](std::int64_t begin, std::int64_t end,
      const std::function<void(std::int64_t, std::int64_t)>& body)
    {
      for (std::int64_t b = begin; b < end; b += 5)
      {
        body(b, std::min(end, b + 5));
      }
    },
    boxPacked);
  Check(boxPacked == mediso::PackVolumeRows(box.data(), boxPoints, static_cast<int>(sizeof(T)), {}),
    Shape(points) + ": PackVolumeBox() of a " + Shape(boxPoints) +
      " box is the box copied out, then packed");
  if (boxPoints[0] >= 2 && boxPoints[1] >= 2 && boxPoints[2] >= 2)
  {
    const int cells[3] = { boxPoints[0] - 1, boxPoints[1] - 1, boxPoints[2] - 1 };
    const PyramidLayout layout(cells);
    const mediso::ScalarType type = mediso::ScalarTypeOf<T>();
    mediso::VolumeTiles fromBox, fromPacked;
    fromBox.Compute(type, box.data(), boxPoints, layout, {});
    fromPacked.Compute(
      type, boxPacked.data(), boxPoints, 4 * mediso::PackedVolumeWidth(boxPoints[0]), layout, {});
    bool same = fromBox.GetNumberOfTiles() == fromPacked.GetNumberOfTiles();
    for (const double iso : { -500.0, 0.0, 100.0, 0.25 })
    {
      const mediso::IsoThresholds t = mediso::MakeIsoThresholds(type, { iso });
      for (std::size_t i = 0; same && i < fromBox.GetNumberOfTiles(); ++i)
      {
        same = fromBox.IsActive(t, i) == fromPacked.IsActive(t, i);
      }
    }
    Check(same, Shape(points) + ": the tiles of packed rows are those of the values themselves");
  }
}

// Every cell's crossing, in double precision (a NaN corner crosses nothing).
template<typename T>
bool CellCrosses(const std::vector<T>& v, const int points[3], int x, int y, int z,
  const std::vector<double>& isovalues)
{
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int c = 0; c < 8; ++c)
  {
    const std::size_t id =
      (static_cast<std::size_t>(z + (c >> 2)) * points[1] + y + ((c >> 1) & 1)) * points[0] + x +
      (c & 1);
    const double value = static_cast<double>(v[id]);
    if (std::isnan(value))
    {
      return false;
    }
    lo = std::min(lo, value);
    hi = std::max(hi, value);
  }
  for (double iso : isovalues)
  {
    if (lo < iso && iso <= hi)
    {
      return true;
    }
  }
  return false;
}

template<typename T>
void CheckTiles(const std::vector<T>& values, const int points[3],
  const std::vector<std::vector<double>>& isovalueSets, bool hasNaN)
{
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  const PyramidLayout layout(cells);
  const auto tiles = layout.TileCounts();
  const auto factor = layout.Factor(1);
  const auto packed = layout.Packed(1);
  const int span[2] = { 2 * PyramidLayout::TileTexels * factor[0],
    2 * PyramidLayout::TileTexels * factor[1] };
  const std::size_t numTiles = static_cast<std::size_t>(tiles[0]) * tiles[1] * tiles[2];
  const mediso::ScalarType type = mediso::ScalarTypeOf<T>();
  // A parallel-for that cuts the range in pieces, as a host's would.
  const mediso::GLParallelFor pieces =
    [](std::int64_t begin, std::int64_t end,
      const std::function<void(std::int64_t, std::int64_t)>& body)
  {
    for (std::int64_t b = begin; b < end; b += 3)
    {
      body(b, std::min(end, b + 3));
    }
  };
  mediso::VolumeTiles volumeTiles;
  volumeTiles.Compute(type, values.data(), points, layout, pieces);
  Check(volumeTiles.GetNumberOfTiles() == numTiles, Shape(points) + ": one range per tile");

  for (const auto& isovalues : isovalueSets)
  {
    const mediso::IsoThresholds thresholds = mediso::MakeIsoThresholds(type, isovalues);
    std::vector<char> crossed(numTiles, 0);
    for (int z = 0; z < cells[2]; ++z)
      for (int y = 0; y < cells[1]; ++y)
        for (int x = 0; x < cells[0]; ++x)
        {
          if (CellCrosses(values, points, x, y, z, isovalues))
          {
            crossed[x / span[0] + tiles[0] * (y / span[1] + tiles[1] * (z / factor[2]))] = 1;
          }
        }
    bool exact = true, cover = true;
    std::uint64_t active = 0, activeTexels = 0;
    for (std::size_t t = 0; t < numTiles; ++t)
    {
      const bool on = volumeTiles.IsActive(thresholds, t);
      cover = cover && (on || !crossed[t]);
      exact = exact && on == static_cast<bool>(crossed[t]);
      if (on)
      {
        ++active;
        const int tx = static_cast<int>(t % tiles[0]);
        const int ty = static_cast<int>((t / tiles[0]) % tiles[1]);
        activeTexels +=
          static_cast<std::uint64_t>(std::min((tx + 1) * PyramidLayout::TileTexels, packed[0]) -
            tx * PyramidLayout::TileTexels) *
          (std::min((ty + 1) * PyramidLayout::TileTexels, packed[1]) -
            ty * PyramidLayout::TileTexels);
      }
    }
    std::string what = Shape(points) + ", isovalues";
    for (double iso : isovalues)
    {
      what += " " + std::to_string(iso);
    }
    Check(cover, what + ": every tile with a crossing cell is active");
    if (!hasNaN)
    {
      Check(exact, what + ": a tile is active exactly when one of its cells crosses");
    }

    std::uint64_t drawn = 0;
    const std::vector<std::uint16_t> rectangles =
      volumeTiles.ActiveRectangles(thresholds, pieces, drawn);
    const auto atlas = layout.AtlasSize(1);
    bool inside = rectangles.size() % 12 == 0;
    std::uint64_t texels = 0;
    for (std::size_t r = 0; inside && r < rectangles.size(); r += 12)
    {
      // Two triangles: (x0, y0), (x1, y0), (x0, y1) and (x0, y1), (x1, y0), (x1, y1).
      const int x0 = rectangles[r], y0 = rectangles[r + 1], x1 = rectangles[r + 2],
                y1 = rectangles[r + 5];
      inside = x0 < x1 && y0 < y1 && x1 <= atlas[0] && y1 <= atlas[1];
      texels += static_cast<std::uint64_t>(x1 - x0) * (y1 - y0);
    }
    Check(inside && drawn == active && texels == activeTexels,
      what + ": the rectangles cover the active tiles' texels (" + std::to_string(drawn) + " of " +
        std::to_string(numTiles) + " tiles)");
  }
}

template<typename T>
std::vector<T> RandomVolume(const int points[3], double lo, double hi, std::mt19937& random)
{
  // Smooth enough that tiles differ: a ramp along z plus noise.
  std::uniform_real_distribution<double> noise(0.0, 0.25 * (hi - lo));
  std::vector<T> v(static_cast<std::size_t>(points[0]) * points[1] * points[2]);
  for (int z = 0; z < points[2]; ++z)
    for (int y = 0; y < points[1]; ++y)
      for (int x = 0; x < points[0]; ++x)
      {
        const double ramp =
          lo + 0.75 * (hi - lo) * (x + y + z) / (points[0] + points[1] + points[2]);
        v[(static_cast<std::size_t>(z) * points[1] + y) * points[0] + x] =
          static_cast<T>(std::floor(ramp + noise(random)));
      }
  return v;
}
// ActiveRectangles()'s tasks, as a host's parallel for receives them.
void CheckRectangleTasks(std::mt19937& random)
{
  std::vector<std::pair<std::int64_t, std::int64_t>> calls;
  const mediso::GLParallelFor recording =
    [&calls](std::int64_t begin, std::int64_t end,
      const std::function<void(std::int64_t, std::int64_t)>& body)
  {
    calls.emplace_back(begin, end);
    for (std::int64_t task = begin; task < end; ++task)
    {
      body(task, task + 1);
    }
  };
  const mediso::IsoThresholds thresholds =
    mediso::MakeIsoThresholds(mediso::ScalarType::Int16, { 0.0 });

  // A brick of 120 points with its apron (123 a side): 8 x 8 x 64 tiles, one task.
  const int brickPoints[3] = { 123, 123, 123 };
  const int brickCells[3] = { 122, 122, 122 };
  const auto brick = RandomVolume<std::int16_t>(brickPoints, -1000.0, 1000.0, random);
  const PyramidLayout brickLayout(brickCells);
  mediso::VolumeTiles brickTiles;
  brickTiles.Compute(mediso::ScalarType::Int16, brick.data(), brickPoints, brickLayout, {});
  std::uint64_t serialDrawn = 0, drawn = 0;
  const auto serial = brickTiles.ActiveRectangles(thresholds, {}, serialDrawn);
  const auto tasked = brickTiles.ActiveRectangles(thresholds, recording, drawn);
  Check(calls.size() == 1 && calls[0] == std::make_pair(std::int64_t(0), std::int64_t(1)) &&
      tasked == serial && drawn == serialDrawn && drawn > 0,
    "a brick's " + std::to_string(brickTiles.GetNumberOfTiles()) +
      " tiles are scanned as one task (" + std::to_string(calls.size()) + " calls, the first [" +
      (calls.empty() ? std::string("-")
                     : std::to_string(calls[0].first) + ", " + std::to_string(calls[0].second)) +
      "))");

  // A volume of 1024 x 1024 x 256 cells: 64 x 64 tiles a slice, 128 slices,
  // 2^19 tiles: 8 tasks of 16 slices, the brick's tiles placed across them.
  const int cells[3] = { 1024, 1024, 256 };
  const PyramidLayout layout(cells);
  mediso::VolumeTiles large;
  large.Reset(mediso::ScalarType::Int16, layout);
  const int count[3] = { 8, 8, 64 };
  for (const int z : { 0, 30, 64 })
  {
    const int origin[3] = { 4 * z % 56, 56 - z % 56, z }; // apart in x and y
    large.Place(&brickTiles, origin, count);
  }
  const std::size_t tiles = large.GetNumberOfTiles();
  const std::int64_t tasks =
    static_cast<std::int64_t>((tiles + mediso::VolumeTiles::MinimumTilesPerTask - 1) /
      mediso::VolumeTiles::MinimumTilesPerTask);
  const std::uint64_t brickDrawn = serialDrawn;

  // Compute() and PackVolumeBox() of a brick of 56 points (59 a side: one
  // task) and of 120 (123 a side: 8 tasks of 9 slices of 2 x 123 x 123
  // points, and of 2132 rows of 123 points), against the serial ones.
  const int volumePoints[3] = { 130, 125, 124 };
  const auto volume = RandomVolume<std::int16_t>(volumePoints, -1000.0, 1000.0, random);
  const mediso::IsoThresholds two =
    mediso::MakeIsoThresholds(mediso::ScalarType::Int16, { -300.0, 250.0 });
  for (const int side : { 59, 123 })
  {
    const int boxPoints[3] = { side, side, side };
    const int boxCells[3] = { side - 1, side - 1, side - 1 };
    const int extent[6] = { 3, 2 + side, 1, side, 0, side - 1 };
    const std::size_t points = static_cast<std::size_t>(side) * side * side;
    const std::int64_t rowTasks = side == 59 ? 1 : 8;
    std::vector<unsigned char> serialRows, taskedRows;
    mediso::PackVolumeBox(volume.data(), volumePoints, extent, 2, {}, serialRows);
    calls.clear();
    mediso::PackVolumeBox(volume.data(), volumePoints, extent, 2, recording, taskedRows);
    Check(calls.size() == 1 && calls[0] == std::make_pair(std::int64_t(0), rowTasks) &&
        taskedRows == serialRows,
      "PackVolumeBox() of " + std::to_string(points) + " points: " + std::to_string(rowTasks) +
        " task(s) of whole rows, the serial copy");
    const PyramidLayout boxLayout(boxCells);
    mediso::VolumeTiles serialTiles, taskedTiles;
    serialTiles.Compute(mediso::ScalarType::Int16, serialRows.data(), boxPoints,
      4 * mediso::PackedVolumeWidth(side), boxLayout, {});
    calls.clear();
    taskedTiles.Compute(mediso::ScalarType::Int16, serialRows.data(), boxPoints,
      4 * mediso::PackedVolumeWidth(side), boxLayout, recording);
    bool same = calls.size() == 1 && calls[0] == std::make_pair(std::int64_t(0), rowTasks);
    for (const mediso::IsoThresholds* t : { &thresholds, &two })
    {
      std::uint64_t a = 0, b = 0;
      same = same &&
        serialTiles.ActiveRectangles(*t, {}, a) == taskedTiles.ActiveRectangles(*t, {}, b) &&
        a == b && a > 0;
    }
    Check(same,
      "Compute() of " + std::to_string(points) + " points: " + std::to_string(rowTasks) +
        " task(s) of whole slices, the serial ranges");
  }
  calls.clear();
  const auto largeSerial = large.ActiveRectangles(thresholds, {}, serialDrawn);
  const auto largeTasked = large.ActiveRectangles(thresholds, recording, drawn);
  Check(calls.size() == 1 && calls[0] == std::make_pair(std::int64_t(0), tasks) && tasks > 1 &&
      largeTasked == largeSerial && drawn == serialDrawn && drawn == 3 * brickDrawn,
    std::to_string(tiles) + " tiles are scanned in " + std::to_string(tasks) +
      " tasks of at least " + std::to_string(mediso::VolumeTiles::MinimumTilesPerTask) +
      " tiles, with the serial scan's rectangles");
}
} // namespace

int main()
{
  std::mt19937 random(7);
  CheckRectangleTasks(random);
  const int shapes[][3] = { { 2, 2, 2 }, { 5, 3, 2 }, { 41, 37, 33 }, { 70, 19, 6 },
    { 18, 66, 9 } };
  for (const auto& points : shapes)
  {
    const auto shorts = RandomVolume<std::int16_t>(points, -1000.0, 1000.0, random);
    CheckPacking(shorts, points);
    CheckTiles(
      shorts, points, { { 0.0 }, { -400.5, 300.0 }, { -2000.0 }, { 200.0, 400.0, 600.0 } }, false);
    const auto bytes = RandomVolume<std::uint8_t>(points, 0.0, 255.0, random);
    CheckPacking(bytes, points);
    CheckTiles(bytes, points, { { 100.0 }, { 30.5, 180.0 } }, false);
    auto floats = RandomVolume<float>(points, -1.0, 1.0, random);
    floats[floats.size() / 3] = std::numeric_limits<float>::quiet_NaN();
    CheckPacking(floats, points);
    CheckTiles(floats, points, { { 0.0 }, { -0.5, 0.25 } }, true);
  }
  return medical_test::Finish("VolumeTiles core: all checks passed");
}
