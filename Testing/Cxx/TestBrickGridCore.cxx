// SPDX-License-Identifier: BSD-3-Clause
// The brick store's core (BrickGrid.h) without VTK: owned extents tile odd
// volumes exactly (every point once, partial last bricks), read extents and
// the bricks they touch against a brute-force definition, brick ranges against
// brute force on a random volume with NaN values (and a brick whose range just
// misses an isovalue has no crossing cell), the copy/write round trip, the
// residency's least-recently-used eviction and over-budget refusal, and bad
// brick sizes rejected.
#include "BrickGrid.h"
#include "MedicalTestUtilities.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

std::string Name(const int points[3], int brick)
{
  return std::to_string(points[0]) + "x" + std::to_string(points[1]) + "x" +
    std::to_string(points[2]) + " in bricks of " + std::to_string(brick);
}

// Every point owned by exactly one brick, and the owner is the brick whose
// extent holds it; bricks are full but the last on an axis.
void CheckTiling(const int points[3], int brickPoints)
{
  const mediso::BrickGrid grid(points, brickPoints);
  const std::string name = Name(points, brickPoints);
  Check(grid.IsValid(), name + ": valid");
  std::vector<int> owners(static_cast<std::size_t>(points[0]) * points[1] * points[2], 0);
  std::uint64_t ownedBytes = 0;
  for (std::int64_t b = 0; b < grid.GetNumberOfBricks(); ++b)
  {
    int e[6];
    grid.OwnedPoints(b, e);
    int index[3];
    grid.BrickIndex(b, index);
    Check(grid.BrickId(index[0], index[1], index[2]) == b, name + ": id round trip");
    for (int a = 0; a < 3; ++a)
    {
      const bool last = index[a] == grid.GetBricksPerAxis()[a] - 1;
      const int size = e[2 * a + 1] - e[2 * a] + 1;
      Check(e[2 * a] == index[a] * brickPoints, name + ": brick starts on its multiple");
      Check(last ? size >= 1 && size <= brickPoints : size == brickPoints,
        name + ": full bricks but the last");
    }
    for (int z = e[4]; z <= e[5]; ++z)
    {
      for (int y = e[2]; y <= e[3]; ++y)
      {
        for (int x = e[0]; x <= e[1]; ++x)
        {
          ++owners[(static_cast<std::size_t>(z) * points[1] + y) * points[0] + x];
        }
      }
    }
    ownedBytes += grid.OwnedBytes(b, 2);
  }
  Check(std::all_of(owners.begin(), owners.end(), [](int n) { return n == 1; }),
    name + ": every point owned exactly once");
  Check(ownedBytes == 2 * owners.size(), name + ": owned bytes add up to the volume's");
  int outside[6];
  grid.OwnedPoints(grid.GetNumberOfBricks(), outside);
  Check(outside[0] > outside[1], name + ": an id past the grid owns nothing");
}

// ReadPoints and BricksTouching against their definitions, point by point.
void CheckReadPoints(const int points[3], int brickPoints, int apron)
{
  const mediso::BrickGrid grid(points, brickPoints);
  const std::string name = Name(points, brickPoints) + ", apron " + std::to_string(apron);
  for (std::int64_t b = 0; b < grid.GetNumberOfBricks(); ++b)
  {
    int owned[6], read[6];
    grid.OwnedPoints(b, owned);
    grid.ReadPoints(b, apron, read);
    for (int a = 0; a < 3; ++a)
    {
      Check(read[2 * a] == std::max(owned[2 * a] - apron, 0) &&
          read[2 * a + 1] == std::min(owned[2 * a + 1] + 1 + apron, points[a] - 1),
        name + ": read extent is owned + 1 on the + side, apron each side, clamped");
    }
    // The owners of the read points, found point by point.
    std::vector<std::int64_t> expected;
    for (int z = read[4]; z <= read[5]; ++z)
    {
      for (int y = read[2]; y <= read[3]; ++y)
      {
        for (int x = read[0]; x <= read[1]; ++x)
        {
          expected.push_back(grid.BrickId(x / brickPoints, y / brickPoints, z / brickPoints));
        }
      }
    }
    std::sort(expected.begin(), expected.end());
    expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
    Check(grid.BricksTouching(read) == expected, name + ": bricks touching the read extent");
    Check(std::find(expected.begin(), expected.end(), b) != expected.end(),
      name + ": a brick reads its own points");
  }
  const int empty[6] = { 5, 4, 0, 0, 0, 0 };
  Check(grid.BricksTouching(empty).empty(), name + ": an empty extent touches nothing");
  const int beyond[6] = { -100, 1 << 20, -3, 1 << 20, -1, 1 << 20 };
  Check(grid.BricksTouching(beyond).size() == static_cast<std::size_t>(grid.GetNumberOfBricks()),
    name + ": an extent over the whole volume is clamped and touches every brick");
}

// Whether a cell (first corner x, y, z) crosses iso: min < iso <= max over its
// 8 corners, and none of them NaN (the GPU's and BlockLOD's convention).
bool CellCrosses(const std::vector<float>& v, const int n[3], int x, int y, int z, double iso)
{
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (int c = 0; c < 8; ++c)
  {
    const float value =
      v[(static_cast<std::size_t>(z + (c >> 2)) * n[1] + y + ((c >> 1) & 1)) * n[0] + x + (c & 1)];
    if (std::isnan(value))
    {
      return false;
    }
    lo = std::min(lo, static_cast<double>(value));
    hi = std::max(hi, static_cast<double>(value));
  }
  return lo < iso && iso <= hi;
}

void CheckRanges()
{
  const int n[3] = { 37, 21, 19 };
  const mediso::BrickGrid grid(n, 8);
  std::mt19937 random(31);
  std::uniform_real_distribution<float> value(-100.f, 100.f);
  std::vector<float> v(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  for (float& x : v)
  {
    x = random() % 13 == 0 ? std::nanf("") : value(random);
  }
  // One brick (the second along x) whose every read point is NaN: its range is empty.
  {
    int read[6];
    grid.ReadPoints(1, 1, read);
    for (int z = read[4]; z <= read[5]; ++z)
      for (int y = read[2]; y <= read[3]; ++y)
        for (int x = read[0]; x <= read[1]; ++x)
          v[(static_cast<std::size_t>(z) * n[1] + y) * n[0] + x] = std::nanf("");
  }
  for (int apron : { 0, 1 })
  {
    const auto ranges = mediso::ComputeBrickRanges(
      grid, mediso::ScalarType::Float32, v.data(), apron, mediso::SerialFor);
    const auto threaded =
      mediso::ComputeBrickRanges(grid, mediso::ScalarType::Float32, v.data(), apron,
        [](std::int64_t b, std::int64_t e, const mediso::RangeBody& body)
        {
          // Two uneven pieces, as a threaded host would cut it.
          const std::int64_t mid = b + (e - b) / 3;
          body(mid, e);
          body(b, mid);
        });
    Check(ranges.size() == static_cast<std::size_t>(grid.GetNumberOfBricks()), "a range per brick");
    for (std::int64_t b = 0; b < grid.GetNumberOfBricks(); ++b)
    {
      int read[6];
      grid.ReadPoints(b, apron, read);
      double lo = std::numeric_limits<double>::infinity();
      double hi = -lo;
      for (int z = read[4]; z <= read[5]; ++z)
        for (int y = read[2]; y <= read[3]; ++y)
          for (int x = read[0]; x <= read[1]; ++x)
          {
            const float x0 = v[(static_cast<std::size_t>(z) * n[1] + y) * n[0] + x];
            if (!std::isnan(x0))
            {
              lo = std::min(lo, static_cast<double>(x0));
              hi = std::max(hi, static_cast<double>(x0));
            }
          }
      const bool same = ranges[b].Min == lo && ranges[b].Max == hi;
      Check(same, "brick " + std::to_string(b) + ": range equals brute force");
      Check(threaded[b].Min == ranges[b].Min && threaded[b].Max == ranges[b].Max,
        "brick " + std::to_string(b) + ": same range in pieces");
    }
    Check(ranges[1].Min > ranges[1].Max, "an all-NaN brick has Min > Max");
    Check(!mediso::BrickCrosses(ranges[1], { -1e300, 0.0, 1e300 }),
      "no isovalue crosses an all-NaN brick");

    // A brick whose range just misses an isovalue has no crossing cell; and
    // every crossing cell lies in an active brick.
    const int brick = static_cast<int>(grid.BrickId(2, 1, 1));
    const double justAbove = std::nextafter(ranges[brick].Max, 1e300);
    const double atMin = ranges[brick].Min; // min < iso fails at iso == min
    const auto above = mediso::ActiveBricks(ranges, { justAbove });
    Check(!std::binary_search(above.begin(), above.end(), brick),
      "a brick is not active just above its maximum");
    Check(!mediso::BrickCrosses(ranges[brick], { atMin }), "nor at its minimum");
    Check(mediso::BrickCrosses(ranges[brick], { ranges[brick].Max }), "but at its maximum");
    for (const double iso : { justAbove, atMin, 0.0, 37.5 })
    {
      const auto active = mediso::ActiveBricks(ranges, { std::nan(""), iso });
      std::int64_t missed = 0, cellsInInactive = 0;
      for (int z = 0; z + 1 < n[2]; ++z)
        for (int y = 0; y + 1 < n[1]; ++y)
          for (int x = 0; x + 1 < n[0]; ++x)
          {
            const std::int64_t owner = grid.BrickId(x / 8, y / 8, z / 8);
            if (CellCrosses(v, n, x, y, z, iso) &&
              !std::binary_search(active.begin(), active.end(), owner))
            {
              ++missed;
            }
            cellsInInactive += owner == brick;
          }
      Check(missed == 0,
        "iso " + std::to_string(iso) + ": every crossing cell's brick is active (" +
          std::to_string(missed) + " missed)");
      Check(cellsInInactive > 0, "the checked brick has cells");
    }
  }
  // Integer data, with the extremes of its type.
  {
    const int m[3] = { 9, 9, 9 };
    const mediso::BrickGrid small(m, 8);
    std::vector<std::int32_t> ints(729, 5);
    ints[0] = std::numeric_limits<std::int32_t>::lowest();
    ints[728] = std::numeric_limits<std::int32_t>::max();
    const auto r = mediso::ComputeBrickRanges(small, mediso::ScalarType::Int32, ints.data(), 1, {});
    Check(r.size() == 8 && r[0].Min == std::numeric_limits<std::int32_t>::lowest() &&
        r[0].Max == std::numeric_limits<std::int32_t>::max() && r[7].Min == 5 &&
        r[7].Max == std::numeric_limits<std::int32_t>::max(),
      "int32 extremes exact, with an empty parallel-for run serially");
  }
}

void CheckCopyWrite()
{
  const int n[3] = { 19, 17, 10 };
  const mediso::BrickGrid grid(n, 8);
  std::vector<std::uint16_t> volume(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  for (std::size_t i = 0; i < volume.size(); ++i)
  {
    volume[i] = static_cast<std::uint16_t>(i * 7 + 3);
  }
  std::vector<std::uint16_t> assembled(volume.size(), 0);
  // Bricks in reverse order, half as owned points, half with their apron.
  for (std::int64_t b = grid.GetNumberOfBricks() - 1; b >= 0; --b)
  {
    int e[6];
    if (b % 2)
    {
      grid.OwnedPoints(b, e);
    }
    else
    {
      grid.ReadPoints(b, 1, e);
    }
    std::vector<std::uint16_t> brick(mediso::BrickGrid::ExtentPoints(e));
    Check(mediso::CopyBrick(grid, b, e, volume.data(), 2, brick.data()), "copy accepted");
    bool same = true;
    std::size_t i = 0;
    for (int z = e[4]; z <= e[5]; ++z)
      for (int y = e[2]; y <= e[3]; ++y)
        for (int x = e[0]; x <= e[1]; ++x)
          same = same && brick[i++] == volume[(static_cast<std::size_t>(z) * n[1] + y) * n[0] + x];
    Check(same, "brick " + std::to_string(b) + ": copied values are the volume's");
    Check(mediso::WriteBrick(grid, b, e, 2, brick.data(), assembled.data()), "write accepted");
  }
  Check(assembled == volume, "bricks written back assemble the volume");
  // Writing a brick touches only its owned points.
  std::vector<std::uint16_t> blank(volume.size(), 0);
  int read[6], owned[6];
  grid.ReadPoints(4, 1, read);
  grid.OwnedPoints(4, owned);
  std::vector<std::uint16_t> brick(mediso::BrickGrid::ExtentPoints(read));
  mediso::CopyBrick(grid, 4, read, volume.data(), 2, brick.data());
  mediso::WriteBrick(grid, 4, read, 2, brick.data(), blank.data());
  Check(std::count_if(blank.begin(), blank.end(), [](std::uint16_t x) { return x != 0; }) ==
      static_cast<std::ptrdiff_t>(mediso::BrickGrid::ExtentPoints(owned)),
    "a write with an apron writes only the owned points");
  // Bad extents: nothing written.
  const int outside[6] = { 0, 19, 0, 0, 0, 0 };
  const int tooSmall[6] = { owned[0] + 1, owned[1], owned[2], owned[3], owned[4], owned[5] };
  std::vector<std::uint16_t> guard(volume.size(), 9);
  Check(!mediso::CopyBrick(grid, 0, outside, volume.data(), 2, guard.data()) &&
      !mediso::CopyBrick(grid, -1, owned, volume.data(), 2, guard.data()) &&
      !mediso::WriteBrick(grid, 4, tooSmall, 2, brick.data(), guard.data()) &&
      !mediso::WriteBrick(grid, 4, outside, 2, brick.data(), guard.data()) &&
      std::all_of(guard.begin(), guard.end(), [](std::uint16_t x) { return x == 9; }),
    "an extent outside the volume, a bad id, or an extent without the owned points is refused");
}

void CheckResidency()
{
  mediso::BrickResidency residency;
  residency.SetBudget(100);
  std::vector<std::int64_t> evicted;
  Check(residency.MakeResident(1, 40, evicted) && residency.MakeResident(2, 30, evicted) &&
      residency.MakeResident(3, 30, evicted) && evicted.empty(),
    "three bricks fit 100 bytes");
  Check(residency.GetResidentBytes() == 100, "100 bytes resident");
  residency.Touch(1);  // order now 2, 3, 1
  residency.Touch(42); // not resident: nothing
  Check(residency.MakeResident(4, 50, evicted) && evicted == std::vector<std::int64_t>({ 2, 3 }),
    "the least recently used go first, oldest first");
  Check(residency.IsResident(1) && residency.IsResident(4) && !residency.IsResident(2) &&
      residency.GetResidentBytes() == 90,
    "touched brick kept");
  evicted.clear();
  Check(!residency.MakeResident(5, 101, evicted) && evicted.empty() &&
      residency.GetResidentBytes() == 90 && !residency.IsResident(5),
    "a brick alone over the budget is refused and evicts nothing");
  Check(residency.MakeResident(1, 60, evicted) && evicted == std::vector<std::int64_t>({ 4 }) &&
      residency.GetResidentBytes() == 60,
    "a resident brick re-made with more bytes evicts others, not itself");
  Check(residency.MakeResident(6, 40, evicted) &&
      residency.GetResidentBricks() == std::vector<std::int64_t>({ 1, 6 }),
    "exactly the budget fits");
  Check(residency.Evict(1) && !residency.Evict(1) && residency.GetResidentBytes() == 40,
    "an evicted brick's bytes are freed once");
  residency.Clear();
  Check(residency.GetResidentBytes() == 0 && residency.GetNumberOfResidentBricks() == 0, "clear");
}
} // namespace

int main()
{
  const int sizes[][3] = { { 37, 21, 19 }, { 8, 8, 8 }, { 1, 1, 1 }, { 16, 33, 9 }, { 64, 3, 17 } };
  for (const auto& n : sizes)
  {
    for (int brick : { 8, 16, 32 })
    {
      CheckTiling(n, brick);
      for (int apron : { 0, 1, 2 })
      {
        CheckReadPoints(n, brick, apron);
      }
    }
  }
  {
    const int n[3] = { 37, 21, 19 };
    const mediso::BrickGrid grid(n, 16);
    Check(grid.GetBricksPerAxis()[0] == 3 && grid.GetBricksPerAxis()[1] == 2 &&
        grid.GetBricksPerAxis()[2] == 2 && grid.GetNumberOfBricks() == 12,
      "37x21x19 in 16s: 3 x 2 x 2 bricks");
    int e[6];
    grid.OwnedPoints(11, e);
    Check(e[0] == 32 && e[1] == 36 && e[2] == 16 && e[3] == 20 && e[4] == 16 && e[5] == 18,
      "the last brick is the partial corner");
    Check(grid.OwnedBytes(11, 2) == 2 * 5 * 5 * 3, "its bytes");
  }
  CheckRanges();
  CheckCopyWrite();
  CheckResidency();

  // Invalid brick sizes and lattices.
  const int n[3] = { 10, 10, 10 };
  const int bad[3] = { 10, 0, 10 };
  for (int brick : { 0, -8, 4, 12, 7 })
  {
    const mediso::BrickGrid grid(n, brick);
    Check(!grid.IsValid() && grid.GetNumberOfBricks() == 0 &&
        mediso::ComputeBrickRanges(grid, mediso::ScalarType::UInt8, n, 0, {}).empty(),
      "brick size " + std::to_string(brick) + " rejected");
  }
  Check(!mediso::BrickGrid(bad, 8).IsValid(), "an empty axis is rejected");
  Check(!mediso::BrickGrid().IsValid(), "a default grid is invalid");
  return medical_test::Finish("BrickGrid core: tiling, read extents, ranges, copies, residency");
}
