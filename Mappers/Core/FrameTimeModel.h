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
 * costs differ in kind, not only in size. A translucent frame blended in one
 * pass (FrameWork::Blended: VTK's weighted blended order-independent
 * transparency, which ParaView's render view draws when depth peeling is off)
 * is a third kind per method, with its own a, b, c: it has no peels, so it
 * costs far less than a peeled frame, but more than an opaque one (issue 30:
 * a Block LOD level-2 frame of the head CT took 1.6 times the opaque frame's
 * renderer time on llvmpipe), and counting it as either kind mispredicts it
 * and pulls that kind's fit.
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
 * over the 8 supports of the three coefficients; a coefficient the frames
 * would make negative is not determined by them and keeps the anchor's value,
 * below, rather than zero). A frame sequence rarely
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
 * drawn another way (opaque for translucent and back, the opaque for a
 * blended pair) scale theirs, else as
 * the other method's do: how fast this machine is transfers, a fitted split
 * does not (a translucent frame's split differs in kind from an opaque one's:
 * depth peeling's full-viewport passes). Before any frame at all the prior
 * predicts, so a host's first interactive frame errs on the coarse side; a
 * GPU's first observed frame scales it down at once.
 *
 * One-off work (issue 30: the misses of the frames a host chose were the
 * frames that switch level). The first frame at a level pays for making it
 * before it draws: a GPU volume level's pyramid (the coarse copy, its upload
 * and the build passes), a Block LOD level's extraction and the upload of its
 * triangles, the programs a new variant compiles. A host says so in the
 * frame's work (BuildElements, Programs, ExtractSeconds) both when it asks
 * for a prediction and when it reports the frame, and the model predicts the
 * whole frame: the drawing, as above, plus
 *
 *     seconds = p * Programs + e * BuildElements + x * ExtractSeconds
 *
 * per method (a GPU level's cells and a level's triangles are elements of a
 * different cost), x the ratio of the estimator's seconds to this machine's.
 * A frame with one-off work is kept apart from the drawing frames: what it
 * took beyond the drawing fit's prediction for it (recomputed at each refit,
 * so a drawing fit that learns the new level corrects it) is fitted for
 * (p, e, x) the same way as the drawing (the same robust, recency-weighted,
 * non-negative fit anchored to OneOffPrior()). Its first frame at a pair
 * with no drawing frame yet teaches the drawing as well: the frame is split
 * between the two in proportion to their predictions, so the next frame is
 * not predicted from the bare prior again. So does a frame that took less
 * than its drawing alone is predicted to take (one-off work cannot take less
 * than nothing, so the drawing fit is wrong there): a first frame whose
 * one-off work was far over its prediction (a shader compile on a software
 * WebGL2) otherwise seeds a drawing fit many times too slow, which frames
 * that always make something (a level switched to) never correct. And so
 * does a frame that draws more primitives or pixels than any drawing frame
 * of its pair: the split there is the fit's extrapolation, and the frame is
 * the only news of that work. Where the host timed the build on its own (a
 * GPU pyramid build ends in a read-back), it says so (Observe with
 * buildSeconds) and nothing is split by prediction: the build is a one-off
 * sample of its own and the rest of the frame a drawing sample (issue 30:
 * every full-volume frame the page's GPU path drew before a drag built its
 * pyramid, so the drawing fit had only coarse levels to extrapolate from).
 *
 * Choose() picks on the drawing alone: the level a drag can hold, whose
 * one-off work is paid once (choosing on the whole frame would keep a drag on
 * whatever level is already made, and never reach the finer one). A host
 * whose every candidate has to be made anyway (an isovalue's first answer)
 * uses ChooseWholeFrame(). A drag's later frames use ChooseHeld(): the
 * candidate drawn last is kept while its prediction is within HoldMargin of
 * the budget, so that predictions moving by a frame's noise do not switch
 * the picture's level or distance on every frame, and a drag goes finer one
 * candidate at a time.
 *
 * Limits: a frame's time also depends on what the counts do not say (overdraw,
 * the depth complexity of translucent layers, caches, other load on the
 * machine); the recency weighting follows slow changes, not frame-to-frame
 * noise. One-off work a host does not report (a driver's own caches) inflates
 * the drawing fit until the robust fit outvotes it. A GPU frame must be timed
 * to its end (a finish or a query), else the CPU time of issuing it is what is
 * learnt.
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
  /// With Translucent: the translucent layers blended in one pass (weighted blended
  /// order-independent transparency: two floating-point targets and one full-viewport resolve)
  /// instead of peeled or sorted; a kind of frame with coefficients of its own (BlendedPrior()).
  bool Blended = false;

  // One-off work, done before the frame draws (0 when it only draws what is made):
  /// Elements the frame makes: the cells of the GPU volume levels whose pyramids it builds
  /// (CellRasterisation), or the triangles it extracts and uploads (Triangles).
  std::uint64_t BuildElements = 0;
  /// Programs the frame compiles (a host counts what compiles: a GPU volume level's pyramid
  /// walk per level and translucency, a mesh program once; a new sample distance compiles none).
  std::uint32_t Programs = 0;
  /// The extraction estimator's seconds for the surfaces the frame extracts (where known).
  double ExtractSeconds = 0.0;
  /// Whether the frame does any one-off work.
  bool HasOneOff() const;
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
  /// The same for translucent frames blended in one pass (FrameWork::Blended).
  static Coefficients BlendedPrior(FrameMethod method);

  /// The three coefficients of a method's one-off work: seconds = PerProgram *
  /// Programs + PerElement * BuildElements + ExtractScale * ExtractSeconds.
  struct OneOffCoefficients
  {
    double PerProgram = 0.0;
    double PerElement = 0.0;
    double ExtractScale = 0.0;
    double Evaluate(const FrameWork& work) const;
  };
  /// The one-off coefficients used before a method's first frame with one-off
  /// work, and the shape their fit is anchored to.
  static OneOffCoefficients OneOffPrior(FrameMethod method);

  /// A measured frame (seconds of rendering it, its one-off work included),
  /// folded into the fit for its method and translucency, or, when it did
  /// one-off work, into its method's one-off fit.
  void Observe(const FrameWork& work, double seconds);
  /// The same for a frame whose BuildElements the host timed on their own,
  /// to their end (`buildSeconds` of `seconds`: a GPU pyramid build that ends
  /// in a read-back): the build is a one-off sample of its own, and the rest
  /// of the frame is observed as a frame without it (a drawing sample where
  /// it made nothing else). A `buildSeconds` that is negative or not finite,
  /// or a frame that builds nothing: Observe(work, seconds).
  void Observe(const FrameWork& work, double seconds, double buildSeconds);
  /// Predicted seconds for a frame, its one-off work included (before any
  /// frame of its method and translucency: its prior, scaled as another
  /// pair's frames scale theirs).
  double Predict(const FrameWork& work) const;
  /// The frame's drawing alone (what the same frame costs once its level is made).
  double PredictDrawing(const FrameWork& work) const;
  /// The frame's one-off work alone (0 when it has none).
  double PredictOneOff(const FrameWork& work) const;
  /// Frames with one-off work currently kept for a method.
  std::size_t OneOffCount(FrameMethod method) const;
  /// The fitted one-off coefficients of a method (before any such frame: the prior).
  OneOffCoefficients FitOneOff(FrameMethod method) const;
  bool HasObservations(FrameMethod method, bool translucent) const;
  /// Frames currently kept for a pair (at most HistoryLength).
  std::size_t ObservationCount(FrameMethod method, bool translucent) const;
  /// Frames currently kept for the kind of frame `kind` is (its method, translucency and
  /// whether it is blended in one pass; its counts do not matter).
  std::size_t ObservationCount(const FrameWork& kind) const;
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
  /// Index of the first candidate (callers order them finest first) whose
  /// drawing is predicted within budgetSeconds, else the last (coarsest): the
  /// level a drag holds, its one-off work paid on its first frame.
  std::size_t Choose(const std::vector<Candidate>& candidates, double budgetSeconds) const;
  /// The same on each candidate's whole frame, its one-off work included: for
  /// a frame whose candidates all have to be made (an isovalue's first answer).
  std::size_t ChooseWholeFrame(
    const std::vector<Candidate>& candidates, double budgetSeconds) const;

  /// How far a held choice's prediction may leave the budget before a drag
  /// gives it up, and how far within it the next finer candidate's must be
  /// before a drag takes that: the accuracy the model is held to (issue 30:
  /// within 25%). Inside that band a prediction does not say on which side
  /// of the budget the frame will fall.
  static constexpr double HoldMargin = 0.25;
  /// The next frame of a drag whose last frame drew candidates[held] (Choose()
  /// or, with `wholeFrame`, ChooseWholeFrame(), where `held` is not an index
  /// of `candidates`): the held candidate stays while its prediction is
  /// within (1 + HoldMargin) x budgetSeconds; with `finer`, the candidate
  /// just finer than it is taken where predicted within budgetSeconds / (1 +
  /// HoldMargin); past the margin, the first coarser candidate predicted
  /// within the budget, else the last. One step finer at a time, because the
  /// candidate next to the frames drawn is the one the model extrapolates
  /// least to; a host stops the steps finer (`finer` false) once its drag has
  /// gone coarser: the finer candidate did not hold on this machine now, and
  /// climbing back to it would flicker.
  std::size_t ChooseHeld(const std::vector<Candidate>& candidates, double budgetSeconds,
    std::size_t held, bool wholeFrame, bool finer) const;

private:
  using Vector3 = std::array<double, 3>;
  // A frame's three counts (the columns its coefficients multiply) and seconds.
  struct Sample
  {
    Vector3 Counts = { { 0.0, 0.0, 0.0 } };
    double Seconds = 0.0;
  };
  struct Pair
  {
    std::deque<Sample> Samples; // oldest first
    Coefficients Fitted;
    double PriorScale = 1.0; // the frames' least-squares ratio to the prior
  };
  // A frame with one-off work: its whole work (its drawing is predicted by
  // its pair's fit at each refit) and seconds.
  struct OneOffSample
  {
    FrameWork Work;
    double Seconds = 0.0;
    // Seconds of the one-off work alone, timed by the host (Observe with
    // buildSeconds): no drawing to take off.
    bool Timed = false;
  };
  struct OneOffFit
  {
    std::deque<OneOffSample> Samples; // oldest first
    OneOffCoefficients Fitted;
  };
  static std::size_t Key(FrameMethod method, bool translucent);
  // The pair of a frame's kind: Key()'s, or its method's blended pair.
  static std::size_t Key(const FrameWork& kind);
  static std::size_t MethodKey(FrameMethod method);
  // What a pair's key names: its method, translucent or not, blended or not.
  struct PairKind
  {
    FrameMethod Method = FrameMethod::CellRasterisation;
    bool Translucent = false;
    bool Blended = false;
  };
  static PairKind KindOf(std::size_t key);
  // The prior of a pair.
  static Coefficients PriorOf(std::size_t key);
  // Keeps a drawing sample in `pair`, the oldest forgotten past HistoryLength.
  static void KeepSample(Pair& pair, const Sample& sample);
  // A pair's prediction before any of its frames: its prior, scaled as the
  // same method drawn another way scales its frames, else as the other
  // method's do, else the prior.
  Coefficients Anchor(std::size_t key) const;
  Coefficients FitOf(std::size_t key) const;
  void Refit(std::size_t key);
  void RefitOneOff(FrameMethod method);
  // Whether a frame with one-off work is also a sample of its pair's drawing:
  // the pair has no drawing frame yet, its drawing alone is predicted longer
  // than the whole frame took, or it draws more primitives or more pixels
  // than any drawing frame the pair keeps.
  bool OneOffTeachesDrawing(const FrameWork& work, double seconds) const;
  // The predicted drawing or whole frame of a candidate (Choose, ChooseWholeFrame).
  double PredictFor(const Candidate& candidate, bool wholeFrame) const;
  // The robust, recency-weighted, non-negative fit of x in counts . x =
  // seconds, anchored to `anchor` scaled to the frames, relative to `prior`.
  static Vector3 Solve(const std::deque<Sample>& samples, const Vector3& prior,
    const Vector3& anchor, double& priorScale);
  static Vector3 SolveWeighted(const std::vector<Vector3>& row, const std::vector<double>& target,
    const std::vector<double>& anchored, const std::vector<double>& weight, const Vector3& anchor,
    double& priorScale);

  // Per method: opaque, translucent (peeled or sorted), translucent blended in one pass.
  std::array<Pair, 6> Pairs;
  std::array<OneOffFit, 2> OneOffs;
};

} // namespace mediso

#endif
