// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FrameTimeModel.h
 * @brief The seconds a frame takes, predicted from the frames already drawn
 * (no VTK, no GL): the time counterpart of the memory estimator, used by every
 * host to pick the level and image sample distance of an interactive frame.
 *
 * What is modelled: one frame of one representation, drawn either by the GPU
 * cell rasteriser (FrameMethod::CellRasterisation: one primitive per active
 * cell-isovalue pair, shaded per covered pixel) or as triangles
 * (FrameMethod::Triangles). Its cost is taken as
 *
 *     seconds = a + b * Primitives + c * Pixels
 *
 * with a the frame's fixed work (state changes, pyramid traversal set-up, the
 * final blit), b the cost of one primitive (vertex work, traversal of the
 * pyramid to find it) and c the cost of one shaded pixel at the image sample
 * distance (Pixels = viewport pixels / distance^2). Each pair (method,
 * translucent) has its own a, b, c: translucent frames sort and blend, so their
 * costs differ in kind, not only in size.
 *
 * Why linear: a rasteriser's work is a sum over primitives and over fragments,
 * and the two counts are what a level (fewer active cells) and a sample
 * distance (fewer pixels) change. Three coefficients are few enough to fit from
 * a handful of frames and to extrapolate to a level or distance not yet drawn,
 * which is the question a host asks before drawing it.
 *
 * How it is fitted: Observe() keeps the last HistoryLength frames of each pair;
 * the coefficients minimise the frames' squared *relative* errors (a 10 ms
 * frame counts as much as a 1 s one), weighted by recency (each newer frame
 * weighs 1 / RecencyDecay times the one before it, so a change of load or of
 * machine is followed within a few frames), with a, b, c >= 0 (solved exactly
 * over the 8 supports of the three coefficients). A frame sequence rarely
 * varies all three counts (a rotation keeps both), so the fit is anchored to
 * the prior, scaled to the frames: a small ridge term pulls (a, b, c) towards
 * s * (a0, b0, c0), s the least-squares scale of the prior to the frames.
 * Directions the frames do not determine keep the prior's shape; directions
 * they determine follow the frames. With one frame (or many with the same work)
 * the prediction is exactly that frame's time scaled by the prior's ratio of
 * the two works; with frames at several levels or distances the split between
 * a, b and c is learnt.
 *
 * The fit is robust: from three frames on it is reweighted, first towards
 * the least absolute deviations (a weighted median: the frames that hold most
 * of the recency weight and agree decide), then with Cauchy's weights on each
 * frame's relative error. A load stall, or a frame with one-off work a host
 * could not tell apart, stops pulling the fit even when it is the newest
 * frame; a lasting change of load, once its frames hold most of the weight
 * (a handful of frames), is followed. A frame at a work not seen before is
 * not an outlier: the split between the coefficients fits it.
 *
 * The anchor is the prior (Prior()), whose shape is a software renderer's
 * (llvmpipe, SwiftShader) as measured and whose size is conservative. A pair
 * without frames predicts its prior scaled as the frames of the same method
 * drawn the other way (opaque for translucent and back) scale theirs, else as
 * the other method's do: how fast this machine is transfers, a fitted split
 * does not (a translucent frame's split differs in kind from an opaque one's:
 * depth peeling's full-viewport passes). Before any frame at all the prior
 * predicts, so a host's first interactive frame errs on the coarse side; a
 * GPU's first observed frame scales it down at once.
 *
 * Limits: a frame's time also depends on what the counts do not say (overdraw,
 * the depth complexity of translucent layers, caches, other load on the
 * machine); the recency weighting follows slow changes, not frame-to-frame
 * noise. Frames that include one-off work (shader compilation, uploads, a
 * pyramid rebuild after an isovalue change) should not be observed, or they
 * inflate the fit until they age out. A GPU frame must be timed to its end
 * (a finish or a query), else the CPU time of issuing it is what is learnt.
 *
 * Bad input never yields NaN or a negative time: non-finite or negative seconds
 * are not observed, zero work predicts the fixed cost a, and Choose() on an
 * empty list returns 0 (callers check the list first).
 */
#ifndef MedicalIsosurfaces_FrameTimeModel_h
#define MedicalIsosurfaces_FrameTimeModel_h

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

namespace mediso
{

/// How a frame draws its surfaces.
enum class FrameMethod
{
  CellRasterisation = 0, ///< the GPU HistoPyramid: one primitive per active cell-isovalue pair
  Triangles = 1          ///< extracted triangles (Block LOD levels, the CPU fallback)
};

/// The work of one frame, what its cost is modelled from.
struct FrameWork
{
  FrameMethod Method = FrameMethod::Triangles;
  std::uint64_t Primitives = 0; ///< active cell-isovalue pairs drawn, or triangles
  std::uint64_t Pixels = 0;     ///< pixels shaded: viewport pixels / (sample distance)^2
  bool Translucent = false;
};

class FrameTimeModel
{
public:
  /// Frames kept per (method, translucent) pair.
  static constexpr std::size_t HistoryLength = 32;
  /// Weight of a frame relative to the next newer one.
  static constexpr double RecencyDecay = 0.8;

  /// The three coefficients of one pair: seconds = Seconds + PerPrimitive *
  /// primitives + PerPixel * pixels.
  struct Coefficients
  {
    double Seconds = 0.0;
    double PerPrimitive = 0.0;
    double PerPixel = 0.0;
    double Evaluate(const FrameWork& work) const;
  };

  /// The pixels a viewport shades at an image sample distance (rounded down, at
  /// least 1 for a non-empty viewport; 0 for an empty one or a distance that is
  /// not finite and positive).
  static std::uint64_t ShadedPixels(int width, int height, double sampleDistance);

  /// The conservative coefficients used before a pair has frames, and the shape
  /// the fit is anchored to.
  static Coefficients Prior(FrameMethod method, bool translucent);

  /// A measured frame (seconds of rendering it), folded into the fit for its
  /// method and translucency.
  void Observe(const FrameWork& work, double seconds);
  /// Predicted seconds for a frame (before any frame of its method and
  /// translucency: its prior, scaled as another pair's frames scale theirs).
  double Predict(const FrameWork& work) const;
  bool HasObservations(FrameMethod method, bool translucent) const;
  /// Frames currently kept for a pair (at most HistoryLength).
  std::size_t ObservationCount(FrameMethod method, bool translucent) const;
  /// The fitted coefficients of a pair (before any frame: its prior, scaled
  /// as another pair's frames scale theirs).
  Coefficients Fit(FrameMethod method, bool translucent) const;
  /// Forgets every frame (another renderer, another window).
  void Reset();

  struct Candidate
  {
    int Level = 0;
    float SampleDistance = 1.0f;
    FrameWork Work;
  };
  /// Index of the first candidate (callers order them finest first) predicted
  /// within budgetSeconds, else the last (coarsest).
  std::size_t Choose(const std::vector<Candidate>& candidates, double budgetSeconds) const;

private:
  struct Sample
  {
    double Primitives = 0.0;
    double Pixels = 0.0;
    double Seconds = 0.0;
  };
  struct Pair
  {
    std::deque<Sample> Samples; // oldest first
    Coefficients Fitted;
    double PriorScale = 1.0; // the frames' least-squares ratio to the prior
  };
  static std::size_t Key(FrameMethod method, bool translucent);
  // A pair's prediction before any of its frames: its prior, scaled as the
  // same method drawn the other way scales its frames, else as the other
  // method's do, else the prior.
  Coefficients Anchor(FrameMethod method, bool translucent) const;
  void Refit(FrameMethod method, bool translucent);
  static Coefficients Solve(const std::deque<Sample>& samples, const Coefficients& prior,
    const Coefficients& anchor, double& priorScale);
  static Coefficients SolveWeighted(const std::vector<std::array<double, 3>>& row,
    const std::vector<double>& target, const std::vector<double>& anchored,
    const std::vector<double>& weight, const Coefficients& anchor, double& priorScale);

  std::array<Pair, 4> Pairs;
};

} // namespace mediso

#endif
