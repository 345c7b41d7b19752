// SPDX-License-Identifier: BSD-3-Clause
#include "FrameTimeModel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mediso
{
namespace
{
// A floor for the prior's seconds of a frame, the divisor of its relative
// error (zero work with a zero prior must not give a frame infinite weight).
constexpr double MinimumSeconds = 1e-6;
// Weight of the pull towards the scaled prior, relative to the frames' total
// weight: small enough that frames spanning all three counts decide, large
// enough to fix the directions they leave open.
constexpr double PriorWeight = 1e-6;
// The robust fit's scale, a frame's relative error (measured / fitted - 1):
// a frame that far off the fit keeps half its weight, one three times as far
// a tenth. Frame-to-frame noise stays well inside it; a stall (another process
// holding the core, a swap that waited) falls outside it and stops pulling
// the fit once the other frames agree among themselves.
constexpr double RobustScale = 0.3;
// Reweighting rounds of the robust fit (each one a solve of a 3x3 system):
// first towards the least absolute deviations, whose minimum is unique (a
// weighted median: the frames holding most of the weight decide, whatever
// the others say), then Cauchy's weights from there.
constexpr int MedianRounds = 8;
constexpr int CauchyRounds = 4;
// Below this relative error a frame's residual counts as this in the median
// rounds (a frame fitted exactly would otherwise take all the weight).
constexpr double MedianFloor = 0.02;

// Frames with one-off work kept per method: each level's first frame, a
// handful per drag; enough to follow a change of load, few enough to refit
// at every frame.
constexpr std::size_t OneOffHistoryLength = 16;

using Vector3 = std::array<double, 3>;
using Matrix3 = std::array<Vector3, 3>;

// Solves the rows and columns of A, b named by `free` (Gaussian elimination
// with partial pivoting); false when singular. Others stay 0.
bool SolveSubset(const Matrix3& a, const Vector3& b, const std::array<bool, 3>& free, Vector3& x)
{
  int index[3];
  int n = 0;
  for (int j = 0; j < 3; ++j)
  {
    if (free[j])
    {
      index[n++] = j;
    }
  }
  double m[3][4];
  for (int r = 0; r < n; ++r)
  {
    for (int c = 0; c < n; ++c)
    {
      m[r][c] = a[index[r]][index[c]];
    }
    m[r][n] = b[index[r]];
  }
  for (int c = 0; c < n; ++c)
  {
    int pivot = c;
    for (int r = c + 1; r < n; ++r)
    {
      if (std::fabs(m[r][c]) > std::fabs(m[pivot][c]))
      {
        pivot = r;
      }
    }
    if (!(std::fabs(m[pivot][c]) > 0.0))
    {
      return false;
    }
    for (int k = 0; k <= n; ++k)
    {
      std::swap(m[c][k], m[pivot][k]);
    }
    for (int r = 0; r < n; ++r)
    {
      if (r != c)
      {
        const double f = m[r][c] / m[c][c];
        for (int k = c; k <= n; ++k)
        {
          m[r][k] -= f * m[c][k];
        }
      }
    }
  }
  x = { 0.0, 0.0, 0.0 };
  for (int r = 0; r < n; ++r)
  {
    x[index[r]] = m[r][n] / m[r][r];
  }
  return true;
}

double Finite(double value, double fallback)
{
  return std::isfinite(value) ? value : fallback;
}

double Dot(const Vector3& a, const Vector3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// A frame's counts in the drawing's columns, and the coefficients as a vector.
Vector3 DrawingCounts(const FrameWork& work)
{
  return { 1.0, static_cast<double>(work.Primitives), static_cast<double>(work.Pixels) };
}
Vector3 AsVector(const FrameTimeModel::Coefficients& c)
{
  return { c.Seconds, c.PerPrimitive, c.PerPixel };
}
FrameTimeModel::Coefficients AsCoefficients(const Vector3& x)
{
  FrameTimeModel::Coefficients c;
  c.Seconds = x[0];
  c.PerPrimitive = x[1];
  c.PerPixel = x[2];
  return c;
}

// The same for one-off work.
Vector3 OneOffCounts(const FrameWork& work)
{
  return { static_cast<double>(work.Programs), static_cast<double>(work.BuildElements),
    std::isfinite(work.ExtractSeconds) ? std::max(0.0, work.ExtractSeconds) : 0.0 };
}
Vector3 AsVector(const FrameTimeModel::OneOffCoefficients& c)
{
  return { c.PerProgram, c.PerElement, c.ExtractScale };
}
FrameTimeModel::OneOffCoefficients AsOneOffCoefficients(const Vector3& x)
{
  FrameTimeModel::OneOffCoefficients c;
  c.PerProgram = x[0];
  c.PerElement = x[1];
  c.ExtractScale = x[2];
  return c;
}
} // namespace

bool FrameWork::HasOneOff() const
{
  return this->BuildElements > 0 || this->Programs > 0 ||
    (std::isfinite(this->ExtractSeconds) && this->ExtractSeconds > 0.0);
}

double FrameTimeModel::OneOffCoefficients::Evaluate(const FrameWork& work) const
{
  const double seconds = Dot(AsVector(*this), OneOffCounts(work));
  if (!(seconds > 0.0))
  {
    return 0.0;
  }
  return std::isfinite(seconds) ? seconds : std::numeric_limits<double>::max();
}

double FrameTimeModel::Coefficients::Evaluate(const FrameWork& work) const
{
  const double seconds = this->Seconds + this->PerPrimitive * static_cast<double>(work.Primitives) +
    this->PerPixel * static_cast<double>(work.Pixels);
  if (!(seconds > 0.0))
  {
    return 0.0;
  }
  return std::isfinite(seconds) ? seconds : std::numeric_limits<double>::max();
}

std::uint64_t FrameTimeModel::ShadedPixels(int width, int height, double sampleDistance)
{
  if (width <= 0 || height <= 0 || !std::isfinite(sampleDistance) || !(sampleDistance > 0.0))
  {
    return 0;
  }
  const double pixels =
    static_cast<double>(width) * static_cast<double>(height) / (sampleDistance * sampleDistance);
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::floor(pixels)));
}

FrameTimeModel::Coefficients FrameTimeModel::Prior(FrameMethod method, bool translucent)
{
  // Software rasterisers, pessimistically: a host's first frames without
  // observations should come out coarse rather than late. Translucent frames
  // blend every layer (and the cell rasteriser sorts), hence the factors.
  //
  // The shape matters more than the size: the first frames a host draws are
  // often all of one work (still frames of the full surface), and what it
  // then predicts for a coarser level is that frame scaled by the prior's
  // ratio of the two works. For triangles the shape is llvmpipe's as measured
  // in ParaView (docs/blocklod.md, issue 30): a frame of a thousandth of the
  // triangles costs about a tenth of the full frame when opaque (the fixed
  // work and the pixels are a small share) and about an eighth when
  // translucent (depth peeling repeats full-viewport passes per layer, so
  // the fixed and per-pixel work grow more than the per-triangle work).
  Coefficients prior;
  if (method == FrameMethod::CellRasterisation)
  {
    prior.Seconds = 0.005;
    prior.PerPrimitive = 6e-7;
    prior.PerPixel = 4e-7;
    if (translucent)
    {
      prior.Seconds *= 3.0;
      prior.PerPrimitive *= 3.0;
      prior.PerPixel *= 3.0;
    }
  }
  else
  {
    prior.Seconds = 0.01;
    prior.PerPrimitive = 3e-7;
    prior.PerPixel = 2.5e-8;
    if (translucent)
    {
      prior.Seconds *= 4.0;
      prior.PerPrimitive *= 4.0;
      prior.PerPixel *= 8.0;
    }
  }
  return prior;
}

FrameTimeModel::Coefficients FrameTimeModel::BlendedPrior(FrameMethod method)
{
  // The opaque prior with the blended pass's work added. Each translucent
  // fragment is blended into two floating-point targets (accumulation and
  // revealage) instead of depth-tested into one, so a triangle costs more;
  // the pass clears those targets, copies the opaque depth and resolves them
  // over the whole viewport, so the fixed and per-pixel work about double.
  // llvmpipe in ParaView (docs/blocklod.md, issue 30): the head CT's level-2
  // frame (262 k triangles, 1024x768) took 1.6 times the opaque frame's
  // renderer time, the level-0 frame (11 k) about twice; these factors give
  // 1.6 and 1.9 at the opaque prior's scale. Far below the peeled prior:
  // there are no peels.
  Coefficients prior = Prior(method, false);
  prior.Seconds *= 2.0;
  prior.PerPrimitive *= 1.5;
  prior.PerPixel *= 2.0;
  return prior;
}

FrameTimeModel::OneOffCoefficients FrameTimeModel::OneOffPrior(FrameMethod method)
{
  // A software renderer's, of the right order rather than exact: the first
  // frame at a new level is predicted from it, and that frame's time then
  // scales it. A program is a compile and link of the isosurface shaders
  // (tens of milliseconds on llvmpipe); a GPU level's cell costs its share of
  // the coarse copy, the upload and the build passes; a triangle its
  // extraction's output and its upload. The estimator's seconds are taken
  // as they are.
  OneOffCoefficients prior;
  prior.PerProgram = 0.03;
  prior.PerElement = method == FrameMethod::CellRasterisation ? 3e-8 : 1e-7;
  prior.ExtractScale = 1.0;
  return prior;
}

std::size_t FrameTimeModel::MethodKey(FrameMethod method)
{
  return method == FrameMethod::CellRasterisation ? 0 : 1;
}

std::size_t FrameTimeModel::Key(FrameMethod method, bool translucent)
{
  const std::size_t m = method == FrameMethod::CellRasterisation ? 0 : 1;
  return 2 * m + (translucent ? 1 : 0);
}

std::size_t FrameTimeModel::Key(const FrameWork& kind)
{
  // The blended pairs follow the four of Key(method, translucent).
  if (kind.Translucent && kind.Blended)
  {
    return 4 + MethodKey(kind.Method);
  }
  return Key(kind.Method, kind.Translucent);
}

FrameTimeModel::PairKind FrameTimeModel::KindOf(std::size_t key)
{
  PairKind kind;
  kind.Blended = key >= 4;
  const std::size_t m = kind.Blended ? key - 4 : key / 2;
  kind.Method = m == 0 ? FrameMethod::CellRasterisation : FrameMethod::Triangles;
  kind.Translucent = kind.Blended || key % 2 == 1;
  return kind;
}

FrameTimeModel::Coefficients FrameTimeModel::PriorOf(std::size_t key)
{
  const PairKind kind = KindOf(key);
  return kind.Blended ? BlendedPrior(kind.Method) : Prior(kind.Method, kind.Translucent);
}

void FrameTimeModel::KeepSample(Pair& pair, const Sample& sample)
{
  pair.Samples.push_back(sample);
  while (pair.Samples.size() > HistoryLength)
  {
    pair.Samples.pop_front();
  }
}

void FrameTimeModel::Observe(const FrameWork& work, double seconds)
{
  if (!std::isfinite(seconds) || seconds < 0.0 ||
    (work.Method != FrameMethod::CellRasterisation && work.Method != FrameMethod::Triangles))
  {
    return;
  }
  Pair& pair = this->Pairs[Key(work)];
  if (work.HasOneOff())
  {
    // Kept apart from the drawing frames, except where the drawing has to
    // learn from it (OneOffTeachesDrawing).
    if (this->OneOffTeachesDrawing(work, seconds))
    {
      const double drawing = this->PredictDrawing(work);
      const double oneOff = this->PredictOneOff(work);
      const double share = drawing + oneOff > 0.0 ? drawing / (drawing + oneOff) : 1.0;
      KeepSample(pair, { DrawingCounts(work), std::max(seconds - oneOff, 0.5 * share * seconds) });
      this->Refit(Key(work));
    }
    OneOffFit& fit = this->OneOffs[MethodKey(work.Method)];
    fit.Samples.push_back({ work, seconds });
    while (fit.Samples.size() > OneOffHistoryLength)
    {
      fit.Samples.pop_front();
    }
    this->RefitOneOff(work.Method);
    return;
  }
  KeepSample(pair, { DrawingCounts(work), seconds });
  this->Refit(Key(work));
  // The one-off frames' residuals are measured against the drawing fit.
  if (!this->OneOffs[MethodKey(work.Method)].Samples.empty())
  {
    this->RefitOneOff(work.Method);
  }
}

void FrameTimeModel::Observe(const FrameWork& work, double seconds, double buildSeconds)
{
  if (!std::isfinite(buildSeconds) || buildSeconds < 0.0 || work.BuildElements == 0 ||
    !std::isfinite(seconds) || seconds < 0.0 ||
    (work.Method != FrameMethod::CellRasterisation && work.Method != FrameMethod::Triangles))
  {
    this->Observe(work, seconds);
    return;
  }
  // Split where the host timed it: nothing of the build is left for the
  // drawing's fit to take, and nothing of the drawing for the build's. An
  // untimed build is split by the two fits' predictions instead, which a frame
  // at a work the drawing fit has not seen cannot settle: on the page's GPU
  // path every full-volume frame before a drag (each isovalue's refinement)
  // built its pyramid, the one-off fit took its drawing as build, and a drag
  // drew the full volume at a distance predicted at 76 ms that took 2.3 s
  // (issue 30, docs/web.md, *The CT's GPU drag*).
  const double build = std::min(buildSeconds, seconds);
  FrameWork built;
  built.Method = work.Method;
  built.Translucent = work.Translucent;
  built.Blended = work.Blended;
  built.BuildElements = work.BuildElements;
  OneOffFit& fit = this->OneOffs[MethodKey(work.Method)];
  fit.Samples.push_back({ built, build, true });
  while (fit.Samples.size() > OneOffHistoryLength)
  {
    fit.Samples.pop_front();
  }
  FrameWork rest = work;
  rest.BuildElements = 0;
  // Refits the one-off fit as well (the sample above is in it).
  this->Observe(rest, seconds - build);
}

bool FrameTimeModel::OneOffTeachesDrawing(const FrameWork& work, double seconds) const
{
  // A pair without a drawing frame yet learns from this one (else its next
  // frame would again be predicted from the prior). So does a pair whose
  // drawing alone is predicted longer than this whole frame took: one-off
  // work takes no less than nothing, so the drawing fit is wrong for this
  // work, and the frame is the only news of it. That happens where a pair's
  // first frame paid one-off work its prediction did not hold (the page's
  // first frame on SwiftShader: a shader compile of seconds, against the
  // prior's tens of milliseconds), so its drawing sample was that frame
  // nearly whole, and every frame after it that drew more also made
  // something (the CPU path uploads each level it switches to): without
  // this, a drawing fit seeded 10-20x too slow met a drag unchanged (issue
  // 30, the 512^3 phantom on the page's CPU path). Taken as the seed is:
  // the frame less its predicted one-off work (the estimator's seconds, or a
  // rate learnt from other levels, are nearer this machine than an unseen
  // pair's prior), but never less than half its share in proportion to the
  // two predictions (one-off work predicted too long must not leave the
  // drawing nothing).
  //
  // And so does a frame that draws more primitives or more pixels than any
  // drawing frame the pair keeps: the fit's prediction for it extrapolates
  // from frames that never drew so much, so the share it leaves to the one-off
  // work is a guess that this frame, the only one of its kind, would confirm.
  // The page's GPU path drew its first full-volume translucent frame (skin
  // over bone) with its program compiled, after only coarse-level frames of
  // that pair: its 4 s were taken as 3.9 s of compile, the next program was
  // predicted at seconds, and the full volume's drawing stayed at the coarse
  // levels' extrapolation (issue 30).
  const Pair& pair = this->Pairs[Key(work)];
  if (pair.Samples.empty() || this->PredictDrawing(work) > seconds)
  {
    return true;
  }
  const Vector3 counts = DrawingCounts(work);
  for (const Sample& s : pair.Samples)
  {
    if (s.Counts[1] >= counts[1] && s.Counts[2] >= counts[2])
    {
      return false;
    }
  }
  return true;
}

void FrameTimeModel::RefitOneOff(FrameMethod method)
{
  // What each one-off frame took beyond its drawing's prediction, by the
  // drawing fit as it stands now; a frame faster than its drawing's
  // prediction says its one-off work was free (the fit's coefficients are
  // non-negative).
  OneOffFit& fit = this->OneOffs[MethodKey(method)];
  std::deque<Sample> residuals;
  for (const OneOffSample& s : fit.Samples)
  {
    residuals.push_back(
      { OneOffCounts(s.Work), s.Timed ? s.Seconds : s.Seconds - this->PredictDrawing(s.Work) });
  }
  const Vector3 prior = AsVector(OneOffPrior(method));
  double scale = 1.0;
  fit.Fitted = AsOneOffCoefficients(Solve(residuals, prior, prior, scale));
}

void FrameTimeModel::Refit(std::size_t key)
{
  Pair& pair = this->Pairs[key];
  double scale = 1.0;
  // Anchored to the prior's shape; the scale found is the frames' ratio to
  // the prior, what a pair without frames borrows (Anchor()).
  const Vector3 prior = AsVector(PriorOf(key));
  pair.Fitted = AsCoefficients(Solve(pair.Samples, prior, prior, scale));
  pair.PriorScale = scale;
}

FrameTimeModel::Coefficients FrameTimeModel::Anchor(std::size_t key) const
{
  // The prior, scaled as the frames of another pair scale theirs: how much
  // faster or slower than the priors this machine is. Only the scale
  // transfers, not a fitted split: a translucent frame's split differs in
  // kind from an opaque one's (depth peeling's full-viewport passes), and a
  // method's from the other's. The same method drawn another way says it
  // first (opaque and peeled each other's, then the blended pair; the
  // blended pair the opaque one, then the peeled); else the other method's
  // opaque or peeled pair with more frames.
  const Coefficients prior = PriorOf(key);
  const PairKind kind = KindOf(key);
  const FrameMethod method = kind.Method;
  const std::size_t siblings[2] = {
    kind.Blended ? Key(method, false) : Key(method, !kind.Translucent),
    kind.Blended ? Key(method, true) : 4 + MethodKey(method) };
  const Pair* source = nullptr;
  for (std::size_t sibling : siblings)
  {
    if (!source && !this->Pairs[sibling].Samples.empty())
    {
      source = &this->Pairs[sibling];
    }
  }
  if (!source)
  {
    const FrameMethod otherMethod = method == FrameMethod::CellRasterisation
      ? FrameMethod::Triangles
      : FrameMethod::CellRasterisation;
    for (bool t : { false, true })
    {
      const Pair& candidate = this->Pairs[Key(otherMethod, t)];
      if (!candidate.Samples.empty() &&
        (!source || candidate.Samples.size() > source->Samples.size()))
      {
        source = &candidate;
      }
    }
  }
  if (source && source->PriorScale > 0.0)
  {
    Coefficients anchor = prior;
    anchor.Seconds *= source->PriorScale;
    anchor.PerPrimitive *= source->PriorScale;
    anchor.PerPixel *= source->PriorScale;
    return anchor;
  }
  return prior;
}

FrameTimeModel::Vector3 FrameTimeModel::Solve(const std::deque<Sample>& samples,
  const Vector3& prior, const Vector3& anchor, double& priorScale)
{
  // Rows in relative terms: frame i asks (a, b, c) . (1, P, X) / p_i = t_i /
  // p_i, p_i the prior's seconds for its work, weighted by recency. Dividing by
  // the prior rather than by the measured t_i makes a 10 ms frame count as
  // much as a 1 s one without favouring fits that predict too little (a
  // measured divisor penalises an overestimate of a frame more than the same
  // factor of underestimate, so a slower machine would be followed late).
  const std::size_t n = samples.size();
  std::vector<double> recency(n);
  std::vector<Vector3> row(n);
  std::vector<double> target(n);
  std::vector<double> anchored(n);
  double w = 1.0;
  for (std::size_t k = n; k-- > 0;)
  {
    const Sample& s = samples[k];
    const double p = std::max(Dot(prior, s.Counts), MinimumSeconds);
    recency[k] = w;
    row[k] = { s.Counts[0] / p, s.Counts[1] / p, s.Counts[2] / p };
    target[k] = s.Seconds / p;
    anchored[k] = Dot(anchor, s.Counts) / p;
    w *= RecencyDecay;
  }

  // Robust reweighting (iteratively reweighted least squares on the log of
  // each frame's measured / fitted ratio): a frame the others contradict, a
  // stall or a first use that a host could not tell apart, loses its pull,
  // even when it is the newest; a frame that only adds a work not seen before
  // is fitted by the split between the coefficients and keeps its weight.
  // The plain fit starts, the median rounds find the frames that agree (a
  // plain fit can sit nearer the outliers when they are recent), Cauchy's
  // rounds weigh those by how well they agree. With fewer than three frames
  // no frame can be outvoted: the plain fit.
  std::vector<double> weight = recency;
  Vector3 fitted = anchor;
  priorScale = 1.0;
  const int rounds = n >= 3 ? 1 + MedianRounds + CauchyRounds : 1;
  for (int round = 0; round < rounds; ++round)
  {
    fitted = SolveWeighted(row, target, anchored, weight, anchor, priorScale);
    if (round + 1 == rounds)
    {
      break;
    }
    for (std::size_t k = 0; k < n; ++k)
    {
      const Sample& s = samples[k];
      const double predicted = std::max(Dot(fitted, s.Counts), MinimumSeconds);
      // The residual in the rows' units (seconds / p_k) over the frame's
      // fitted time in those units: the frame's relative error.
      const double r = (s.Seconds - predicted) / predicted;
      if (round < MedianRounds)
      {
        weight[k] = recency[k] / (row[k][0] * predicted * std::max(std::fabs(r), MedianFloor));
      }
      else
      {
        const double u = r / RobustScale;
        weight[k] = recency[k] / (1.0 + u * u);
      }
    }
  }
  return fitted;
}

FrameTimeModel::Vector3 FrameTimeModel::SolveWeighted(const std::vector<Vector3>& row,
  const std::vector<double>& target, const std::vector<double>& anchored,
  const std::vector<double>& weight, const Vector3& anchor, double& priorScale)
{
  const std::size_t n = row.size();
  double totalWeight = 0.0;
  for (std::size_t k = 0; k < n; ++k)
  {
    totalWeight += weight[k];
  }
  Vector3 scale = { 0.0, 0.0, 0.0 };
  for (std::size_t k = 0; k < n; ++k)
  {
    for (int j = 0; j < 3; ++j)
    {
      scale[j] += weight[k] * row[k][j] * row[k][j];
    }
  }
  for (int j = 0; j < 3; ++j)
  {
    scale[j] = std::sqrt(scale[j] / totalWeight);
    if (!(scale[j] > 0.0) || !std::isfinite(scale[j]))
    {
      scale[j] = 1.0;
    }
  }

  // The anchor's least-squares scale to these frames (with the plain prior as
  // anchor each anchored row is 1, and it is the frames' weighted mean ratio
  // to the prior).
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < n; ++k)
  {
    num += weight[k] * anchored[k] * target[k];
    den += weight[k] * anchored[k] * anchored[k];
  }
  const double anchorScale = den > 0.0 ? Finite(num / den, 1.0) : 1.0;
  priorScale = anchorScale;
  const Vector3 priorPhi = { anchorScale * anchor[0] * scale[0], anchorScale * anchor[1] * scale[1],
    anchorScale * anchor[2] * scale[2] };

  // Normal equations of the scaled problem with the ridge towards the prior.
  const double ridge = PriorWeight * totalWeight;
  Matrix3 a{};
  Vector3 b{};
  for (std::size_t k = 0; k < n; ++k)
  {
    Vector3 z;
    for (int j = 0; j < 3; ++j)
    {
      z[j] = row[k][j] / scale[j];
    }
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        a[r][c] += weight[k] * z[r] * z[c];
      }
      b[r] += weight[k] * z[r] * target[k];
    }
  }
  for (int j = 0; j < 3; ++j)
  {
    a[j][j] += ridge;
    b[j] += ridge * priorPhi[j];
  }

  // Non-negative coefficients, exactly: the objective is strictly convex, so
  // where its unconstrained minimum is non-negative it is the fit. Where the
  // frames would make a coefficient negative they do not determine it (no
  // work costs less than nothing: their differences in that count are within
  // their noise), and it keeps the anchor's value, as the directions they
  // leave open do; of the 8 supports (the others at the anchor), the
  // feasible one with the smallest objective. Clamping it to zero instead
  // said the opposite of "not determined": on the 512^3 phantom two frames of
  // one level at distances 4 and 6, 1.6% apart the wrong way, made the pixels
  // free, and volume level 0 at distance 1 was predicted at 0.034 s for a
  // frame of 0.146 s (docs/histopyramid.md, *The 512^3 phantom's frame*).
  // An anchor below zero (the one-off fit's, when its frames took less than
  // their drawing's prediction) is held at zero: nothing costs less than
  // nothing, and the support with every coefficient held stays feasible.
  Vector3 held;
  for (int j = 0; j < 3; ++j)
  {
    held[j] = std::max(0.0, priorPhi[j]);
  }
  Vector3 best = held;
  double bestObjective = std::numeric_limits<double>::infinity();
  for (int mask = 0; mask < 8; ++mask)
  {
    const std::array<bool, 3> free = { (mask & 1) != 0, (mask & 2) != 0, (mask & 4) != 0 };
    // The coefficients outside the support keep the anchor's value: their
    // share of the right-hand side is moved over before solving the others.
    Vector3 rhs = b;
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        if (!free[c])
        {
          rhs[r] -= a[r][c] * held[c];
        }
      }
    }
    Vector3 phi;
    if (!SolveSubset(a, rhs, free, phi))
    {
      continue;
    }
    for (int j = 0; j < 3; ++j)
    {
      if (!free[j])
      {
        phi[j] = held[j];
      }
    }
    bool feasible = true;
    for (int j = 0; j < 3; ++j)
    {
      feasible = feasible && std::isfinite(phi[j]) && phi[j] >= 0.0;
    }
    if (!feasible)
    {
      continue;
    }
    double objective = 0.0;
    for (int r = 0; r < 3; ++r)
    {
      double ar = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        ar += a[r][c] * phi[c];
      }
      objective += phi[r] * ar - 2.0 * b[r] * phi[r];
    }
    if (objective < bestObjective)
    {
      bestObjective = objective;
      best = phi;
    }
  }

  Vector3 fitted;
  for (int j = 0; j < 3; ++j)
  {
    fitted[j] = Finite(best[j] / scale[j], anchor[j]);
  }
  return fitted;
}

double FrameTimeModel::Predict(const FrameWork& work) const
{
  const double seconds = this->PredictDrawing(work) + this->PredictOneOff(work);
  return std::isfinite(seconds) ? seconds : std::numeric_limits<double>::max();
}

double FrameTimeModel::PredictDrawing(const FrameWork& work) const
{
  if (work.Method != FrameMethod::CellRasterisation && work.Method != FrameMethod::Triangles)
  {
    return Prior(FrameMethod::CellRasterisation, true).Evaluate(work);
  }
  return this->FitOf(Key(work)).Evaluate(work);
}

double FrameTimeModel::PredictOneOff(const FrameWork& work) const
{
  if (!work.HasOneOff())
  {
    return 0.0;
  }
  if (work.Method != FrameMethod::CellRasterisation && work.Method != FrameMethod::Triangles)
  {
    return OneOffPrior(FrameMethod::Triangles).Evaluate(work);
  }
  return this->FitOneOff(work.Method).Evaluate(work);
}

std::size_t FrameTimeModel::OneOffCount(FrameMethod method) const
{
  if (method != FrameMethod::CellRasterisation && method != FrameMethod::Triangles)
  {
    return 0;
  }
  return this->OneOffs[MethodKey(method)].Samples.size();
}

FrameTimeModel::OneOffCoefficients FrameTimeModel::FitOneOff(FrameMethod method) const
{
  if (method != FrameMethod::CellRasterisation && method != FrameMethod::Triangles)
  {
    return OneOffPrior(FrameMethod::Triangles);
  }
  const OneOffFit& fit = this->OneOffs[MethodKey(method)];
  return fit.Samples.empty() ? OneOffPrior(method) : fit.Fitted;
}

bool FrameTimeModel::HasObservations(FrameMethod method, bool translucent) const
{
  return this->ObservationCount(method, translucent) > 0;
}

std::size_t FrameTimeModel::ObservationCount(FrameMethod method, bool translucent) const
{
  return this->Pairs[Key(method, translucent)].Samples.size();
}

FrameTimeModel::Coefficients FrameTimeModel::Fit(FrameMethod method, bool translucent) const
{
  return this->FitOf(Key(method, translucent));
}

FrameTimeModel::Coefficients FrameTimeModel::FitOf(std::size_t key) const
{
  const Pair& pair = this->Pairs[key];
  return pair.Samples.empty() ? this->Anchor(key) : pair.Fitted;
}

std::size_t FrameTimeModel::ObservationCount(const FrameWork& kind) const
{
  if (kind.Method != FrameMethod::CellRasterisation && kind.Method != FrameMethod::Triangles)
  {
    return 0;
  }
  return this->Pairs[Key(kind)].Samples.size();
}

void FrameTimeModel::Reset()
{
  for (Pair& pair : this->Pairs)
  {
    pair.Samples.clear();
    pair.Fitted = Coefficients();
    pair.PriorScale = 1.0;
  }
  for (OneOffFit& fit : this->OneOffs)
  {
    fit.Samples.clear();
    fit.Fitted = OneOffCoefficients();
  }
}

std::size_t FrameTimeModel::Choose(
  const std::vector<Candidate>& candidates, double budgetSeconds) const
{
  if (candidates.empty())
  {
    return 0;
  }
  for (std::size_t i = 0; i < candidates.size(); ++i)
  {
    if (this->PredictDrawing(candidates[i].Work) <= budgetSeconds)
    {
      return i;
    }
  }
  return candidates.size() - 1;
}

std::size_t FrameTimeModel::ChooseWholeFrame(
  const std::vector<Candidate>& candidates, double budgetSeconds) const
{
  if (candidates.empty())
  {
    return 0;
  }
  for (std::size_t i = 0; i < candidates.size(); ++i)
  {
    if (this->Predict(candidates[i].Work) <= budgetSeconds)
    {
      return i;
    }
  }
  return candidates.size() - 1;
}

double FrameTimeModel::PredictFor(const Candidate& candidate, bool wholeFrame) const
{
  return wholeFrame ? this->Predict(candidate.Work) : this->PredictDrawing(candidate.Work);
}

std::size_t FrameTimeModel::ChooseHeld(const std::vector<Candidate>& candidates,
  double budgetSeconds, std::size_t held, bool wholeFrame, bool finer) const
{
  if (held >= candidates.size())
  {
    return wholeFrame ? this->ChooseWholeFrame(candidates, budgetSeconds)
                      : this->Choose(candidates, budgetSeconds);
  }
  // Why a band and not the budget itself: the choice follows the model's
  // predictions, which move with every frame observed, so a drag whose
  // candidates sit near the budget switched on each frame's noise (the CT's
  // GPU drag went through distances 4, 6, 8 and 1 and volume levels 0, 3 and
  // -1 in 19 frames, a flickering picture). Why one step finer: a candidate
  // far from every frame drawn is the fit's extrapolation along counts those
  // frames hardly varied (the same drag's level 0 at every pixel, predicted
  // at 85 ms from frames at distances 4 to 8, took 633 ms). Why no step finer
  // after a step coarser (the host's `finer`): on a loaded machine a step
  // finer predicted within the band took 2-5x its prediction, the next frame
  // went back, and the drag went up and down between distances 2 and 6.
  const double predicted = this->PredictFor(candidates[held], wholeFrame);
  if (predicted <= budgetSeconds * (1.0 + HoldMargin))
  {
    if (finer && held > 0 &&
      this->PredictFor(candidates[held - 1], wholeFrame) <= budgetSeconds / (1.0 + HoldMargin))
    {
      return held - 1;
    }
    return held;
  }
  for (std::size_t i = held + 1; i < candidates.size(); ++i)
  {
    if (this->PredictFor(candidates[i], wholeFrame) <= budgetSeconds)
    {
      return i;
    }
  }
  return candidates.size() - 1;
}

} // namespace mediso
