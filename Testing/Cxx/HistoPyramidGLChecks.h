// SPDX-License-Identifier: BSD-3-Clause
// The checks of the GPU core's HistoPyramid (mediso::HistoPyramidGL) against
// the CPU model mediso::HistoPyramid, node for node, in whatever context is
// current: TestHistoPyramidGLCore runs them on EGL contexts of OpenGL ES 3.0
// and OpenGL 3.2 core (no VTK, no X display), TestHistoPyramidGLVTKWindow inside a
// VTK render window. For the phantom stored as each supported scalar type and
// many isovalue sets (single isovalues across the range, isovalues equal to
// data values and just beside them, sets of 2 to 8, duplicates, NaN), and for
// thin int16 volumes (3x40x17, 40x2x9, 2x2x30 points: axes that reach one
// node early): the total, every level, the level-1 tiles drawn and, where
// one isovalue is counted, level 1's child masks bit for bit against the
// CPU's base level. Also that the GL state is left as it was, that Release()
// then a new upload and build work, and the GPU memory of a 256^3 volume.
#ifndef HistoPyramidGLChecks_h
#define HistoPyramidGLChecks_h

#include "GLApiFunctions.h"
#include "GLProbe.h"
#include "HeadPhantom.h"
#include "HistoPyramid.h"
#include "HistoPyramidGL.h"
#include "MedicalTestUtilities.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace pyramid_checks
{
using medical_test::Check;

inline std::vector<std::int16_t> MakePhantom(const int dims[3], double noise, std::uint32_t seed)
{
  const mediso::HeadPhantom phantom(dims, noise, seed);
  std::vector<std::int16_t> values(static_cast<std::size_t>(phantom.GetNumberOfPoints()));
  const int extent[6] = { 0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1 };
  std::vector<double> scratch(static_cast<std::size_t>(dims[0]));
  phantom.FillSlices(extent, 0, dims[2], values.data(), scratch.data());
  return values;
}

// Cells crossed by each isovalue (min < iso <= max over the 8 corners, none NaN), summed.
template <typename T>
inline std::uint64_t BruteForceCount(
  const std::vector<T>& v, const int n[3], const std::vector<double>& isos)
{
  std::uint64_t count = 0;
  for (int z = 0; z + 1 < n[2]; ++z)
    for (int y = 0; y + 1 < n[1]; ++y)
      for (int x = 0; x + 1 < n[0]; ++x)
      {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        bool nan = false;
        for (int c = 0; c < 8; ++c)
        {
          const double value = static_cast<double>(
            v[(static_cast<std::size_t>(z + (c >> 2)) * n[1] + y + ((c >> 1) & 1)) * n[0] + x +
              (c & 1)]);
          nan = nan || std::isnan(value);
          lo = std::min(lo, value);
          hi = std::max(hi, value);
        }
        for (const double iso : isos)
        {
          count += !nan && lo < iso && iso <= hi;
        }
      }
  return count;
}

inline std::string Describe(const std::vector<double>& isovalues)
{
  std::ostringstream os;
  os.precision(17);
  os << "{";
  for (std::size_t i = 0; i < isovalues.size(); ++i)
  {
    os << (i ? ", " : "") << isovalues[i];
  }
  os << "}";
  return os.str();
}

// Isovalue sets for data of range [lo, hi] containing the given values.
inline std::vector<std::vector<double>> IsovalueSets(
  double lo, double hi, const std::vector<double>& data)
{
  std::vector<std::vector<double>> sets;
  // Single isovalues: outside, at the ends, evenly across the range.
  sets.push_back({ lo - 1.0 });
  sets.push_back({ lo });
  sets.push_back({ hi });
  sets.push_back({ hi + 1.0 });
  for (int n = 1; n < 12; ++n)
  {
    sets.push_back({ lo + (hi - lo) * n / 12.0 });
  }
  // Equal to data values, and just beside them.
  for (std::size_t i = 0; i < data.size(); i += 97)
  {
    const double v = data[i];
    sets.push_back({ v });
    sets.push_back({ std::nextafter(v, -HUGE_VAL) });
    sets.push_back({ std::nextafter(v, HUGE_VAL) });
    if (sets.size() > 40)
    {
      break;
    }
  }
  const double q1 = lo + (hi - lo) * 0.25, q2 = lo + (hi - lo) * 0.5, q3 = lo + (hi - lo) * 0.75;
  // Sets of 2 to 4, in and out of order, with duplicates and NaN; one of 8.
  sets.push_back({ q1, q3 });
  sets.push_back({ q3, q1, q2 });
  sets.push_back({ data[data.size() / 2], q1, hi, lo });
  sets.push_back({ q2, q2 });
  sets.push_back({ std::numeric_limits<double>::quiet_NaN(), q2 });
  sets.push_back({ -1.0e300, q1, 1.0e300 });
  std::vector<double> eight;
  for (int n = 0; n < 8; ++n)
  {
    eight.push_back(lo + (hi - lo) * (n + 0.5) / 8.0);
  }
  sets.push_back(eight);
  return sets;
}

// Compares one GPU build with the CPU reference; prints one line.
template <typename T>
void CompareBuild(mediso::HistoPyramidGL& gpu, const std::string& name, const T* data,
  const int dims[3], const std::vector<double>& isovalues)
{
  const int cells[3] = { dims[0] - 1, dims[1] - 1, dims[2] - 1 };
  mediso::HistoPyramid cpu;
  cpu.Build(cells, mediso::HistoPyramid::CountCrossings(data, dims, isovalues));

  const std::string what = name + " " + Describe(isovalues);
  int mismatches = 0;
  std::string firstMismatch, error;
  const std::uint64_t total = gpu.GetTotal();
  if (gpu.GetLayout().GetNumberOfLevels() != cpu.GetNumberOfLevels())
  {
    Check(false, what + ": " + std::to_string(gpu.GetLayout().GetNumberOfLevels()) +
        " levels, CPU " + std::to_string(cpu.GetNumberOfLevels()));
    return;
  }
  for (int l = 0; l < cpu.GetNumberOfLevels(); ++l)
  {
    std::vector<std::uint32_t> counts;
    int size[3] = { 0, 0, 0 };
    if (!gpu.ReadLevel(l, counts, size, false, error))
    {
      Check(false, what + ": level " + std::to_string(l) + " cannot be read back: " + error);
      return;
    }
    const int* expected = cpu.GetLevelSize(l);
    if (size[0] != expected[0] || size[1] != expected[1] || size[2] != expected[2])
    {
      Check(false, what + ": level " + std::to_string(l) + " has a different size");
      return;
    }
    std::size_t id = 0;
    for (int k = 0; k < size[2]; ++k)
      for (int j = 0; j < size[1]; ++j)
        for (int i = 0; i < size[0]; ++i, ++id)
        {
          const std::uint32_t want = cpu.GetCount(l, i, j, k);
          if (counts[id] != want && mismatches++ == 0)
          {
            std::ostringstream os;
            os << "level " << l << " node (" << i << ", " << j << ", " << k << "): GPU "
               << counts[id] << ", CPU " << want;
            firstMismatch = os.str();
          }
        }
  }
  // The level-1 pass draws only the tiles (TileTexels^2 packed texels, twice
  // as many nodes per side, of one slice) whose value range holds an
  // isovalue. The points of a tile are connected by cell edges, so its range
  // holds an isovalue exactly when one of its cells crosses it: without NaN
  // values, the tiles drawn are exactly those with a non-zero level-1 node
  // (with NaN values, at least those).
  const int tileNodes = 2 * mediso::PyramidLayout::TileTexels;
  const int* one = cpu.GetLevelSize(1);
  const int tiles[3] = { (one[0] + tileNodes - 1) / tileNodes, (one[1] + tileNodes - 1) / tileNodes,
    one[2] };
  std::vector<char> activeTile(static_cast<std::size_t>(tiles[0]) * tiles[1] * tiles[2], 0);
  for (int k = 0; k < one[2]; ++k)
    for (int j = 0; j < one[1]; ++j)
      for (int i = 0; i < one[0]; ++i)
      {
        if (cpu.GetCount(1, i, j, k) != 0)
        {
          activeTile[(static_cast<std::size_t>(k) * tiles[1] + j / tileNodes) * tiles[0] +
            i / tileNodes] = 1;
        }
      }
  const std::uint64_t expectedTiles =
    static_cast<std::uint64_t>(std::count(activeTile.begin(), activeTile.end(), 1));
  bool hasNaN = false;
  const std::size_t numPoints = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  for (std::size_t i = 0; i < numPoints && !hasNaN; ++i)
  {
    hasNaN = std::isnan(static_cast<double>(data[i]));
  }
  const std::uint64_t drawn = gpu.GetLastTilesDrawn();
  std::cout << what << ": total GPU " << total << " CPU " << cpu.GetTotal() << ", "
            << cpu.GetNumberOfLevels() << " levels, "
            << (mismatches ? std::to_string(mismatches) + " node mismatches" : "all nodes equal")
            << ", level-1 tiles drawn " << drawn << " of " << gpu.GetNumberOfTiles()
            << " (with an active cell: " << expectedTiles << ")\n";
  Check(total == cpu.GetTotal(), what + ": totals differ");
  Check(mismatches == 0, what + ": " + firstMismatch);
  Check(gpu.GetNumberOfTiles() == activeTile.size(), what + ": unexpected number of tiles");
  Check(hasNaN ? drawn >= expectedTiles : drawn == expectedTiles,
    what + ": the level-1 pass drew " + std::to_string(drawn) + " tiles, not " +
      std::to_string(expectedTiles));

  // With one counted isovalue (and a level 2), level 1 holds child masks:
  // bit dx + 2 dy + 4 dz of node n set exactly when its child cell
  // n * factor + (dx, dy, dz) is active in the CPU's base level. The counts
  // above only check the number of bits; the walk reads the bits.
  const bool masksExpected = gpu.GetCountedIsovalues().size() == 1 && cpu.GetNumberOfLevels() >= 3;
  Check(gpu.GetLevelOneHoldsChildMasks() == masksExpected,
    what + ": level 1 should hold " + (masksExpected ? "child masks" : "counts"));
  if (gpu.GetLevelOneHoldsChildMasks())
  {
    std::vector<std::uint32_t> stored;
    int size[3] = { 0, 0, 0 };
    if (!gpu.ReadLevel(1, stored, size, true, error))
    {
      Check(false, what + ": level 1 cannot be read back as stored: " + error);
      return;
    }
    const int* base = cpu.GetLevelSize(0);
    const int factor[3] = { base[0] / one[0], base[1] / one[1], base[2] / one[2] };
    int maskMismatches = 0;
    std::size_t id = 0;
    for (int k = 0; k < one[2]; ++k)
      for (int j = 0; j < one[1]; ++j)
        for (int i = 0; i < one[0]; ++i, ++id)
        {
          std::uint32_t want = 0;
          for (int c = 0; c < 8; ++c)
          {
            const int d[3] = { c & 1, (c >> 1) & 1, (c >> 2) & 1 };
            if (d[0] < factor[0] && d[1] < factor[1] && d[2] < factor[2] &&
              cpu.GetCount(0, i * factor[0] + d[0], j * factor[1] + d[1], k * factor[2] + d[2]) != 0)
            {
              want |= 1u << c;
            }
          }
          maskMismatches += stored[id] != want ? 1 : 0;
        }
    Check(maskMismatches == 0,
      what + ": " + std::to_string(maskMismatches) + " level-1 child masks differ from the CPU's");
  }
}

// One scalar type: upload, then every isovalue set.
template <typename T>
void RunType(mediso::HistoPyramidGL& gpu, const std::string& name, const std::vector<T>& values,
  const int dims[3])
{
  std::string error;
  if (!gpu.UploadVolume(mediso::ScalarTypeOf<T>(), values.data(), dims, nullptr, error))
  {
    Check(false, name + ": UploadVolume failed: " + error);
    return;
  }
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  std::vector<double> asDouble;
  asDouble.reserve(values.size());
  for (T v : values)
  {
    const double d = static_cast<double>(v);
    asDouble.push_back(d);
    if (!std::isnan(d))
    {
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  for (const auto& isovalues : IsovalueSets(lo, hi, asDouble))
  {
    if (!gpu.Build(isovalues, error))
    {
      Check(false, name + " " + Describe(isovalues) + ": Build failed: " + error);
      continue;
    }
    CompareBuild(gpu, name, values.data(), dims, isovalues);
  }
  // What a host is told before it uploads (the web page chooses its level by it) is what the
  // uploaded and built volume holds.
  const std::uint64_t estimate =
    mediso::HistoPyramidGL::EstimateGPUMemoryBytes(mediso::ScalarTypeOf<T>(), dims);
  Check(gpu.IsBuilt() && gpu.GetGPUMemoryBytes() == estimate,
    name + ": EstimateGPUMemoryBytes " + std::to_string(estimate) + " but GetGPUMemoryBytes " +
      std::to_string(gpu.GetGPUMemoryBytes()));
}

template <typename T, typename F>
std::vector<T> Convert(const std::vector<std::int16_t>& hu, F f)
{
  std::vector<T> out(hu.size());
  std::transform(hu.begin(), hu.end(), out.begin(), f);
  return out;
}

template <typename T>
T Clamp(double v)
{
  return static_cast<T>(std::min<double>(
    std::max<double>(v, std::numeric_limits<T>::lowest()), std::numeric_limits<T>::max()));
}

// The state a build must leave as it was.
struct StateSnapshot
{
  GLint Viewport[4] = { 0, 0, 0, 0 };
  GLint Draw = 0, Read = 0, Program = 0, VertexArray = 0, ActiveTexture = 0, Texture3D = 0;
  GLint Unpack = 0;
  GLboolean Depth = GL_FALSE, Blend = GL_FALSE, Scissor = GL_FALSE;

  explicit StateSnapshot(const mediso::GLApi& gl)
  {
    const auto& f = gl.F();
    f.GetIntegerv(GL_VIEWPORT, this->Viewport);
    f.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &this->Draw);
    f.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &this->Read);
    f.GetIntegerv(GL_CURRENT_PROGRAM, &this->Program);
    f.GetIntegerv(GL_VERTEX_ARRAY_BINDING, &this->VertexArray);
    f.GetIntegerv(GL_ACTIVE_TEXTURE, &this->ActiveTexture);
    f.GetIntegerv(GL_TEXTURE_BINDING_3D, &this->Texture3D);
    f.GetIntegerv(GL_UNPACK_ALIGNMENT, &this->Unpack);
    this->Depth = f.IsEnabled(GL_DEPTH_TEST);
    this->Blend = f.IsEnabled(GL_BLEND);
    this->Scissor = f.IsEnabled(GL_SCISSOR_TEST);
  }
  bool operator==(const StateSnapshot& o) const
  {
    return std::equal(this->Viewport, this->Viewport + 4, o.Viewport) && this->Draw == o.Draw &&
      this->Read == o.Read && this->Program == o.Program && this->VertexArray == o.VertexArray &&
      this->ActiveTexture == o.ActiveTexture && this->Texture3D == o.Texture3D &&
      this->Unpack == o.Unpack && this->Depth == o.Depth && this->Blend == o.Blend &&
      this->Scissor == o.Scissor;
  }
};

/// Every check, in the current context of `gl`; returns the test's exit code.
inline int RunAll(const std::shared_ptr<const mediso::GLApi>& gl, const char* passed)
{
  std::cout << "context: " << gl->Describe() << "\n";
  std::string reason;
  Check(mediso::ProbeGL(*gl, reason) == mediso::ProbeResult::Passed, "the probe fails: " + reason);
  // The phantom, odd sizes on every axis, with noise so that many values occur.
  const int dims[3] = { 45, 38, 29 };
  const std::vector<std::int16_t> hu = MakePhantom(dims, 20.0, 7u);
  {
    mediso::HistoPyramidGL gpu(gl);

    const StateSnapshot before(*gl);
    RunType<std::int16_t>(gpu, "int16", hu, dims);
    Check(StateSnapshot(*gl) == before, "the OpenGL state is not restored after a build");

    RunType<std::uint8_t>(gpu, "uint8",
      Convert<std::uint8_t>(hu, [](std::int16_t v) { return Clamp<std::uint8_t>((v + 1024) / 9); }),
      dims);
    RunType<std::int8_t>(gpu, "int8",
      Convert<std::int8_t>(hu, [](std::int16_t v) { return Clamp<std::int8_t>(v / 9); }), dims);
    RunType<std::uint16_t>(gpu, "uint16",
      Convert<std::uint16_t>(hu, [](std::int16_t v) { return Clamp<std::uint16_t>(v + 1024); }),
      dims);
    // Large 32-bit values: comparisons in float would merge neighbouring values.
    RunType<std::int32_t>(gpu, "int32",
      Convert<std::int32_t>(hu, [](std::int16_t v) { return static_cast<std::int32_t>(v) * 100003; }),
      dims);
    RunType<std::uint32_t>(gpu, "uint32",
      Convert<std::uint32_t>(
        hu, [](std::int16_t v) { return static_cast<std::uint32_t>(v + 1024) * 1000003u + 7u; }),
      dims);
    // Float: non-integer values, and a few NaN points (their cells count 0).
    std::vector<float> floats =
      Convert<float>(hu, [](std::int16_t v) { return static_cast<float>(v) * 0.1f + 0.05f; });
    for (std::size_t i = 1234; i < floats.size(); i += 4567)
    {
      floats[i] = std::numeric_limits<float>::quiet_NaN();
    }
    RunType<float>(gpu, "float", floats, dims);
    // Double (converted to float on the GPU; these values are exact in float).
    RunType<double>(gpu, "double",
      Convert<double>(hu, [](std::int16_t v) { return static_cast<double>(v) + 0.5; }), dims);

    // Thin volumes, where an axis reaches one node before the others (or has
    // one cell from the start): the stored levels pack 2x2 nodes in x and y
    // to a texel, and along such an axis half of each texel is a node beyond
    // the level, which must count 0.
    const std::vector<std::array<int, 3>> thinShapes = { { 3, 40, 17 }, { 40, 2, 9 }, { 2, 2, 30 } };
    for (const auto& shape : thinShapes)
    {
      const std::vector<std::int16_t> thin = MakePhantom(shape.data(), 20.0, 5u);
      RunType<std::int16_t>(gpu, "int16 " + std::to_string(shape[0]) + "x" +
          std::to_string(shape[1]) + "x" + std::to_string(shape[2]),
        thin, shape.data());
    }

    // Release everything, then upload and build again.
    gpu.Release();
    Check(gpu.GetGPUMemoryBytes() == 0 && !gpu.IsBuilt() && gpu.GetTotal() == 0,
      "Release() left resources behind");
    std::string error;
    const std::vector<double> isovalues = { 300.0, -500.0 };
    const bool ok = gpu.UploadVolume(mediso::ScalarType::Int16, hu.data(), dims, nullptr, error) &&
      gpu.Build(isovalues, error);
    Check(ok, "upload and build after Release() failed: " + error);
    if (ok)
    {
      CompareBuild(gpu, "int16 after release", hu.data(), dims, isovalues);
    }

    // GPU memory of a 256^3 int16 volume (and its total against the CPU).
    const int big[3] = { 256, 256, 256 };
    const std::vector<std::int16_t> bigHU = MakePhantom(big, 20.0, 11u);
    const std::vector<double> bone = { 300.0 };
    const bool bigOk = gpu.UploadVolume(mediso::ScalarType::Int16, bigHU.data(), big, nullptr, error) &&
      gpu.Build(bone, error);
    Check(bigOk, "256^3 upload and build failed: " + error);
    if (bigOk)
    {
      const int cells[3] = { 255, 255, 255 };
      mediso::HistoPyramid cpu;
      cpu.Build(cells, mediso::HistoPyramid::CountCrossings(bigHU.data(), big, bone));
      const double volumeBytes = 2.0 * 256 * 256 * 256;
      std::cout << "256^3 int16, isovalue 300: total GPU " << gpu.GetTotal() << " CPU "
                << cpu.GetTotal() << ", " << gpu.GetLayout().GetNumberOfLevels()
                << " levels, GPU memory " << gpu.GetGPUMemoryBytes() << " bytes ("
                << static_cast<double>(gpu.GetGPUMemoryBytes()) / volumeBytes << "x the volume)\n";
      Check(gpu.GetTotal() == cpu.GetTotal(), "256^3 totals differ");
      Check(gpu.GetGPUMemoryBytes() <= 1.5 * volumeBytes, "256^3: GPU memory over 1.5x the volume");
    }
  }
  // A pyramid destroyed without Release() frees its objects itself (no error).
  {
    mediso::HistoPyramidGL scoped(gl);
    std::string error;
    Check(scoped.UploadVolume(mediso::ScalarType::Int16, hu.data(), dims, nullptr, error) &&
        scoped.Build({ 100.0 }, error),
      "build of a second, unreleased pyramid failed: " + error);
  }
  Check(gl->TakeErrors().empty(), "OpenGL errors left behind");
  return medical_test::Finish(passed);
}

} // namespace pyramid_checks

#endif
