// SPDX-License-Identifier: BSD-3-Clause
// The frame-time model fed the frames the page's worker gives it on the CPU
// path (issue 30: the 512^3 phantom and the head CT, skin at opacity 0.3 over
// bone, 1024x768, SwiftShader), in the order the worker observed them
// (WebViewer::Finish: each frame's triangles, shaded pixels, translucency and
// one-off work), with times from a cost of known coefficients fitted to the
// lead's quiet frames, and the drag's frames chosen as the worker chooses them
// (WebViewer::ChooseFrame: the levels from the memory's down, then level 0 at
// sample distances 1.5 to 8, the first whose whole frame fits 100 ms).
//
// What failed: the page's first frame compiles the meshes' program, which on
// SwiftShader takes seconds against the one-off prior's 30 ms, so the
// translucent pair's first drawing sample was that frame nearly whole; every
// frame after it until the drag made something (a level switched to uploads
// its triangles), so the drawing fit never heard of them, and the drag began
// with its level-0 frames predicted about ten times too slow (the quiet run:
// 325 ms predicted for 31 ms, a median error of 32% over the drag on the
// phantom; on the CT, 114 ms for 18 ms, then two level-3 frames of 0.38 s
// predicted at 57-525 ms, the fit having heard of level 0 only).
#include "FrameTimeModel.h"
#include "MedicalTestUtilities.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using mediso::FrameMethod;
using mediso::FrameTimeModel;
using mediso::FrameWork;

std::string Number(double value)
{
  char text[64];
  std::snprintf(text, sizeof(text), "%.4g", value);
  return text;
}

constexpr int Width = 1024, Height = 768;

// The page's frames of an input's surfaces on this client, drawing and
// one-off work: a translucent frame of triangles costs a fixed part, its
// triangles and its shaded pixels (the coefficients fitted to the quiet
// run's drag and still frames of each input); the meshes' program compiles
// in 1.5 s; a triangle uploads in 20 ns; an extraction takes 1.2 times the
// estimator's seconds.
struct Client
{
  double Fixed, PerTriangle, PerPixel;
  double Seconds(const FrameWork& work) const
  {
    const double p = static_cast<double>(work.Primitives);
    const double x = static_cast<double>(work.Pixels);
    return this->Fixed + this->PerTriangle * p + this->PerPixel * x + 1.5 * work.Programs +
      2e-8 * static_cast<double>(work.BuildElements) + 1.2 * work.ExtractSeconds;
  }
};

FrameWork Frame(std::uint64_t triangles, double distance, bool translucent, bool upload,
  double extractSeconds, std::uint32_t programs)
{
  FrameWork work;
  work.Method = FrameMethod::Triangles;
  work.Primitives = triangles;
  work.Pixels = FrameTimeModel::ShadedPixels(Width, Height, distance);
  work.Translucent = translucent;
  work.BuildElements = upload ? triangles : 0;
  work.ExtractSeconds = extractSeconds;
  work.Programs = programs;
  return work;
}

double Median(std::vector<double> values)
{
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The page's session on one input: the works the worker observed before the
// drag (`before`), each timed by `client`, then a drag of 20 frames chosen as
// the worker chooses them from the surfaces' triangles at levels 0-3; checks
// the drag's predictions against the frames' times.
void Session(const char* input, const Client& client, const std::vector<FrameWork>& before,
  const std::uint64_t (&triangles)[4])
{
  FrameTimeModel model;
  for (const FrameWork& work : before)
  {
    model.Observe(work, client.Seconds(work));
  }

  // The drag: the worker's candidates and choice, the frame's prediction as
  // the worker reports it (its upload included where the level changes),
  // then the frame observed.
  int shownLevel = 3;
  std::vector<double> errors;
  double slowest = 0.0;
  std::string listing;
  for (int move = 0; move < 20; ++move)
  {
    std::vector<FrameTimeModel::Candidate> candidates;
    for (int level = 3; level >= 0; --level)
    {
      FrameTimeModel::Candidate c;
      c.Level = level;
      c.Work = Frame(triangles[level], 1.0, true, false, 0.0, 0);
      candidates.push_back(c);
    }
    for (double distance : { 1.5, 2.0, 3.0, 4.0, 6.0, 8.0 })
    {
      FrameTimeModel::Candidate c;
      c.Level = 0;
      c.SampleDistance = static_cast<float>(distance);
      c.Work = Frame(triangles[0], distance, true, false, 0.0, 0);
      candidates.push_back(c);
    }
    const FrameTimeModel::Candidate chosen = candidates[model.ChooseWholeFrame(candidates, 0.1)];
    FrameWork work = chosen.Work;
    work.BuildElements = chosen.Level == shownLevel ? 0 : work.Primitives;
    shownLevel = chosen.Level;
    const double predicted = model.Predict(work);
    const double measured = client.Seconds(work);
    errors.push_back(std::fabs(predicted - measured) / measured);
    slowest = std::max(slowest, measured);
    listing += " L" + std::to_string(chosen.Level) + "/d" + Number(chosen.SampleDistance) + " " +
      Number(1000 * predicted) + "/" + Number(1000 * measured);
    model.Observe(work, measured);
  }
  const std::string name = input;
  std::printf("%s: drag frames, level/distance predicted/measured ms:%s\n", input, listing.c_str());
  Check(Median(errors) <= 0.25,
    name + ": the drag's frames predicted within 25% (median " + Number(100 * Median(errors)) +
      "%)");
  // The old model's CT drag drew two frames at level 3 (0.38-0.40 s), which
  // a drawing fit that had heard of level 0 only predicted at 55-78 ms.
  Check(slowest <= 0.2,
    name + ": no drag frame over twice the budget (the slowest " + Number(1000 * slowest) + " ms)");
  Check(errors.front() <= 0.5,
    name + ": the drag's first frame within 50% (" + Number(100 * errors.front()) + "%)");
}

// The page's GPU path on the head CT (issue 30: the lead's quiet run drew the
// drag at distances 4, 6, 8 and 1 and volume levels 0, 3 and -1, 30% median
// error). A translucent cell-rasterisation frame costs a fixed part, its
// primitives and its shaded pixels (fitted to that run's drag frames: level 0's
// 5,190 primitives in 64 ms at distance 8 and 629 ms at every pixel, the full
// volume's 545,570 at distance 6 in 2.3 s); an opaque one about half; a
// pyramid build a fixed set of passes and its cells; a program 0.3 s (a
// SwiftShader compile). Each frame's time is scaled by the next of a fixed
// series of factors: the same frame's spread in that run (61-118 ms for level
// 0 at distance 6), or a loaded machine's (0.7-1.8x).
struct GPUClient
{
  double Drawing(const FrameWork& work) const
  {
    const double scale = work.Translucent ? 1.0 : 0.5;
    return scale *
      (0.034 + 4.1e-6 * static_cast<double>(work.Primitives) +
        7.3e-7 * static_cast<double>(work.Pixels));
  }
  double Build(const FrameWork& work) const
  {
    return work.BuildElements > 0 ? 0.05 + 1e-7 * static_cast<double>(work.BuildElements) : 0.0;
  }
  double Programs(const FrameWork& work) const { return 0.3 * work.Programs; }
};

// The CT's volume levels, finest first (3: the volume; -1: one point in 16):
// their cells (IsosurfaceScene's samples of 256x256x108 points) and the
// skin-over-bone scene's active pairs.
struct GPULevel
{
  int Level;
  std::uint64_t Cells, Pairs;
};
constexpr GPULevel CTLevels[] = { { 3, 255ull * 255 * 107, 545570 },
  { 2, 128ull * 128 * 54, 130000 }, { 1, 64ull * 64 * 27, 30000 }, { 0, 32ull * 32 * 14, 5190 },
  { -1, 16ull * 16 * 7, 956 } };

FrameWork GPUFrame(std::uint64_t pairs, double distance, bool translucent, std::uint64_t buildCells,
  std::uint32_t programs)
{
  FrameWork work;
  work.Method = FrameMethod::CellRasterisation;
  work.Primitives = pairs;
  work.Pixels = FrameTimeModel::ShadedPixels(Width, Height, distance);
  work.Translucent = translucent;
  work.BuildElements = buildCells;
  work.Programs = programs;
  return work;
}

void GPUSession(const char* name, const std::vector<double>& noise, bool checkError)
{
  const GPUClient client;
  FrameTimeModel model;
  std::size_t frame = 0;
  // A frame observed as the worker does (WebViewer::Finish): its time, and its
  // pyramid build timed on its own (the build ends in a read-back).
  const auto observe = [&](const FrameWork& work)
  {
    const double factor = noise[frame++ % noise.size()];
    const double build = factor * client.Build(work);
    const double seconds = build + factor * (client.Drawing(work) + client.Programs(work));
    model.Observe(work, seconds, build);
    return seconds;
  };
  // Before the drag, the frames the worker drew (the benchmark's run, logged
  // in its frame list): the page's first surfaces (skin -500 at 0.3 over bone
  // 400) answered on level 0 and refined on the volume, the change to 400
  // alone and the timed one to -500 (opaque: answered on level -1, refined),
  // then the drag's scene again: answered on level 0, whose pyramid the first
  // frame built for these surfaces (no one-off work), and refined. Every other
  // frame builds the pyramid of the level it draws; each level and
  // translucency compiles its program once.
  const GPULevel& full = CTLevels[0];
  const GPULevel& zero = CTLevels[3];
  const GPULevel& coarsest = CTLevels[4];
  observe(GPUFrame(zero.Pairs, 1.0, true, zero.Cells, 1));
  observe(GPUFrame(full.Pairs, 1.0, true, full.Cells, 1));
  observe(GPUFrame(420, 8.0, false, coarsest.Cells, 1));
  observe(GPUFrame(320781, 1.0, false, full.Cells, 1));
  observe(GPUFrame(536, 8.0, false, coarsest.Cells, 0));
  observe(GPUFrame(224789, 1.0, false, full.Cells, 0));
  observe(GPUFrame(zero.Pairs, 4.0, true, 0, 0));
  observe(GPUFrame(full.Pairs, 1.0, true, full.Cells, 0));

  // The drag, chosen as the worker chooses (WebViewer::ChooseFrame: every
  // level at distances 1 to 8, finest first, on the whole frame; each frame
  // after the first holding the last one's candidate, FrameTimeModel::ChooseHeld).
  // The levels built for these surfaces: the volume and level 0.
  std::vector<int> built = { 3, 0 };
  std::vector<int> warm = { 3, 0 }; // translucent programs compiled
  std::vector<double> errors;
  double slowest = 0.0;
  int switches = 0;
  std::size_t held = ~std::size_t(0);
  bool finer = true; // until the drag goes coarser
  std::string listing;
  for (int move = 0; move < 20; ++move)
  {
    std::vector<FrameTimeModel::Candidate> candidates;
    for (const GPULevel& level : CTLevels)
    {
      const bool isBuilt = std::count(built.begin(), built.end(), level.Level) > 0;
      const bool isWarm = std::count(warm.begin(), warm.end(), level.Level) > 0;
      for (double distance : { 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0 })
      {
        FrameTimeModel::Candidate c;
        c.Level = level.Level;
        c.SampleDistance = static_cast<float>(distance);
        c.Work = GPUFrame(level.Pairs, distance, true, isBuilt ? 0 : level.Cells, isWarm ? 0 : 1);
        candidates.push_back(c);
      }
    }
    const std::size_t chosen = model.ChooseHeld(candidates, 0.1, held, true, finer);
    switches += move > 0 && chosen != held ? 1 : 0;
    finer = finer && !(move > 0 && chosen > held);
    held = chosen;
    const FrameWork work = candidates[chosen].Work;
    if (work.BuildElements > 0)
    {
      built.push_back(candidates[chosen].Level);
    }
    if (work.Programs > 0)
    {
      warm.push_back(candidates[chosen].Level);
    }
    const double predicted = model.Predict(work);
    const double measured = observe(work);
    errors.push_back(std::fabs(predicted - measured) / measured);
    slowest = std::max(slowest, measured);
    listing += " L" + std::to_string(candidates[chosen].Level) + "/d" +
      Number(candidates[chosen].SampleDistance) + " " + Number(1000 * predicted) + "/" +
      Number(1000 * measured);
  }
  const std::string prefix = std::string("head CT, GPU path, ") + name;
  std::printf("%s: drag frames, volume level/distance predicted/measured ms:%s\n", prefix.c_str(),
    listing.c_str());
  // Within 25% where the frames themselves spread by about that; a loaded
  // machine's spread is more than any prediction can meet.
  Check(!checkError || Median(errors) <= 0.25,
    prefix + ": the drag's frames predicted within 25% (median " + Number(100 * Median(errors)) +
      "%)");
  // The quiet run's drag drew the volume at distance 6 (predicted 76 ms, 2.3 s)
  // and level 0 at every pixel (predicted 85 ms, 633 ms); a model that splits
  // an untimed build by prediction draws level 1 here (predicted 99 ms, 0.5 s).
  Check(slowest <= 0.2,
    prefix + ": no drag frame over twice the budget (the slowest " + Number(1000 * slowest) +
      " ms)");
  // Choosing each frame afresh switches between distances 4 and 6 (3 to 6
  // times) on the loaded machine's spread.
  Check(switches <= 2,
    prefix + ": the drag keeps its choice (" + std::to_string(switches) +
      " switches of level or distance in 20 frames)");
}
} // namespace

int main()
{
  // The 512^3 phantom (quiet: 31-72 ms for level 0's 71,732 triangles from
  // distance 8 to 1, 844 ms for level 3's 4.6 M). Before the drag, the works
  // the worker observed (logged in WebViewer::Finish): the page's first frame
  // (its program compiled), the warm-up change and the measured change
  // (coarse first answers and their refinements), the drag's scene (its
  // coarse first answer at level 0 and its refinement at level 3): every one
  // of them made something, the surfaces extracted or a level uploaded.
  const std::uint64_t phantom[4] = { 71732, 290000, 1160000, 4606656 };
  Session("phantom 512^3", Client{ 0.025, 1.7e-7, 5.5e-8 },
    {
      Frame(71732, 1.0, true, true, 0.002, 1),
      Frame(4606656, 1.0, true, true, 0.15, 0),
      Frame(4606656, 1.0, true, true, 0.0, 0),
      Frame(43876, 1.0, true, true, 0.002, 0),
      Frame(2821462, 1.0, true, true, 0.0, 0),
      Frame(27856, 1.0, true, true, 0.004, 0),
      Frame(1785194, 1.0, true, true, 0.0, 0),
      Frame(phantom[0], 1.0, true, true, 0.0, 0),
      Frame(phantom[3], 1.0, true, true, 0.0, 0),
    },
    phantom);

  // The head CT (quiet: 18-27 ms for level 0's 10,790 triangles from
  // distance 8 to 2, 69 ms for level 1's 56,730 at every pixel, 371-392 ms
  // for level 3's 1.1 M), the works the worker observed the same way.
  const std::uint64_t ct[4] = { 10790, 56730, 250000, 1108154 };
  Session("head CT", Client{ 0.0142, 2.96e-7, 4.8e-8 },
    {
      Frame(10626, 1.0, true, true, 0.002, 1),
      Frame(1108154, 1.0, true, true, 0.028, 0),
      Frame(5298, 1.0, true, true, 0.001, 0),
      Frame(657174, 1.0, true, true, 0.0, 0),
      Frame(5492, 1.0, true, true, 0.003, 0),
      Frame(450980, 1.0, true, true, 0.0, 0),
      Frame(ct[0], 1.0, true, true, 0.0, 0),
      Frame(ct[3], 1.0, true, true, 0.0, 0),
    },
    ct);

  GPUSession("quiet", { 1.0, 1.15, 0.85, 1.25, 0.9, 1.05, 0.8, 1.2, 0.95, 1.1 }, true);
  GPUSession("loaded", { 1.0, 1.2, 0.8, 1.4, 0.9, 1.1, 0.7, 1.8, 0.95, 1.25, 0.85, 1.5 }, false);
  return medical_test::Finish("passed");
}
