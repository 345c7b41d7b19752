// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FrameFixedCost.h
 * @brief The part of a window's frame that one representation's drawing does
 * not include (no VTK, no GL), measured, so that the representation chooses
 * its interactive level for the budget that is left.
 *
 * A host's frame budget (issue 30: an interactive frame within 0.1 s) is the
 * whole frame a user waits for: the window's clear, the other props, a
 * post-process pass (FXAA), the blit to the window and the swap, and the
 * representation's own drawing. FrameTimeModel predicts the representation's
 * drawing only (its coefficients are fitted to the representation's own timed
 * frames), so a representation that spends the whole budget on its drawing
 * makes a frame over the budget by the window's cost. VTK's volume mappers
 * make the same mistake: vtkGPUVolumeRayCastMapper compares its own time with
 * the prop's allocated render time, which is the whole frame's share.
 *
 * FrameFixedCost keeps the difference, frame by frame:
 *
 *     fixed = window's frame seconds - the representation's own seconds
 *
 * and Seconds() is the median of the last HistoryLength differences. The
 * representation then chooses for BudgetLeft(budget) = budget - Seconds().
 *
 * Why it does not oscillate: the representation's own seconds are timed to
 * the end of its work (glFinish), and they are what the frame-time model is
 * fitted to, so each part of the frame is counted once, either in the model
 * (what a level changes) or here (what it does not). A coarser frame does not
 * make the rest of the window look slower; where some of the window's work
 * does depend on the level (llvmpipe flushes earlier props' drawing at the
 * representation's glFinish), it lands in the model's fixed coefficient, not
 * here. Why a median: a frame stalled by the machine's load, or one that
 * resized or created the window, is one sample of several and moves nothing;
 * a lasting change (another prop shown, FXAA turned on) is followed once it
 * is most of the history (HistoryLength / 2 + 1 frames).
 *
 * Bad input: a non-finite or negative time is not observed; a difference
 * below zero counts as zero (the window cannot cost less than nothing); with
 * no frame observed Seconds() is 0, so a host's first frames choose as they
 * did before the window was measured.
 *
 * FrameTimeSpread, below, keeps the other thing a host takes off its budget:
 * how far its last interactive frames overran their predictions.
 *
 * @sa FrameTimeModel
 */
#ifndef mediso_FrameFixedCost_h
#define mediso_FrameFixedCost_h

#include <array>
#include <cstddef>

namespace mediso
{

/**
 * The last few values a host measured, frame by frame (a ring of
 * HistoryLength), and the k-th smallest of those kept: what FrameFixedCost
 * takes its median of and FrameTimeSpread its quantile of.
 */
class RecentFrameValues
{
public:
  /// The frames kept.
  static constexpr std::size_t HistoryLength = 9;

  /// Keeps `value`, forgetting the oldest once HistoryLength are kept.
  void Push(double value);

  /// How many are kept (at most HistoryLength).
  std::size_t Kept() const;

  /// The `rank`-th smallest of those kept (0: the smallest); 0 when none is kept.
  double Smallest(std::size_t rank) const;

  /// Values pushed so far (all of them, not only those kept).
  std::size_t GetNumberOfFrames() const { return this->Frames; }

  /// Forget every value.
  void Reset();

private:
  std::array<double, HistoryLength> Recent{};
  std::size_t Frames = 0;
};

class FrameFixedCost
{
public:
  /// The frames whose differences the median is taken over.
  static constexpr std::size_t HistoryLength = RecentFrameValues::HistoryLength;

  /**
   * One frame: the window's seconds (its render from start to end) and the
   * representation's own timed seconds within it. Ignored when either is
   * negative or not finite.
   */
  void Observe(double windowSeconds, double ownSeconds);

  /// The window's cost outside the representation: the median of the last frames (0: none).
  double Seconds() const;

  /// `budget` less Seconds(), never below 0 (a non-finite budget is returned as it is).
  double BudgetLeft(double budget) const;

  /// Frames observed so far (all of them, not only those kept).
  std::size_t GetNumberOfFrames() const { return this->Differences.GetNumberOfFrames(); }

  /// Forget every frame (a new window).
  void Reset() { this->Differences.Reset(); }

private:
  RecentFrameValues Differences;
};

/**
 * How far a host's chosen frames overran their predictions, measured on its
 * last interactive frames, and the budget that leaves (issue 30, the 512^3
 * phantom's interactive frame).
 *
 * A host chooses the finest candidate predicted within its budget. Where the
 * candidates near the budget lie close together (a coarse level's frames at
 * sample distances 4 to 8 all cost about its primitives), the chosen frame is
 * predicted right at the budget, and a model that is right on average still
 * puts half the frames over it; a model that misses the scene by a few
 * percent (work it does not count, such as a reduced frame's composite up to
 * the viewport) puts most of them over. The margin is what the frames show,
 * not a constant: each interactive frame without one-off work gives its
 * ratio measured / predicted, and
 *
 *     Margin() = (the Quantile-th of the last HistoryLength ratios) - 1, at least 0
 *     BudgetLeft(budget) = budget / (1 + Margin())
 *
 * so that about three frames in four of a steady drag are predicted to fit
 * with their own measured error. A model that predicts the frames it chose
 * within their noise keeps a margin of that noise (a few percent on llvmpipe);
 * one that over-predicts keeps none. A stalled frame is one ratio of nine and
 * moves the quantile by one place.
 *
 * An overrun is counted against the larger of the frame's prediction and
 * the whole budget it was chosen under (Observe with `budgetSeconds`): a
 * frame predicted at 2 ms that took 6 ms under a 160 ms budget overran by
 * 4 ms, 2.5% of what the next frame may spend, not by 200%. Frames far
 * inside their budget are where a timer's and a loaded machine's noise is
 * largest as a ratio (a coarse frame of a drag that has just left a stall),
 * and their ratios would otherwise halve the budget of the frames near it
 * that follow.
 *
 * Bad input: a ratio that is not finite and positive (a prediction or a time
 * not finite or not positive) is not observed; with none observed the margin
 * is 0 and the budget is returned as it is.
 */
class FrameTimeSpread
{
public:
  /// The frames whose ratios the quantile is taken over.
  static constexpr std::size_t HistoryLength = RecentFrameValues::HistoryLength;
  /// The quantile of the ratios the margin is taken at (three frames in four).
  static constexpr double Quantile = 0.75;

  /// One interactive frame: its predicted and measured seconds (its drawing
  /// only), and the whole frame budget it was chosen under (before this
  /// margin and the window's cost were taken off; 0: none, the prediction
  /// alone). The kept ratio is 1 + (measured - predicted) / max(predicted,
  /// budget).
  void Observe(double predictedSeconds, double measuredSeconds, double budgetSeconds = 0.0);

  /// The measured overrun the next choice allows for (0: none, or no frame yet).
  double Margin() const;

  /// `budget` / (1 + Margin()) (a non-finite or negative budget is returned as it is).
  double BudgetLeft(double budget) const;

  /// Frames observed so far (all of them, not only those kept).
  std::size_t GetNumberOfFrames() const { return this->Ratios.GetNumberOfFrames(); }

  /// Forget every frame.
  void Reset() { this->Ratios.Reset(); }

private:
  RecentFrameValues Ratios;
};

} // namespace mediso

#endif
