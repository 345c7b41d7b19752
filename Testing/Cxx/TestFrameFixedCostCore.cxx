// SPDX-License-Identifier: BSD-3-Clause
// FrameFixedCost on synthetic frames: the window's cost outside a
// representation is the median of the last frames' differences, a stalled
// frame moves nothing, a lasting change is followed within half the history,
// the budget left never goes below zero, and bad input is not observed.
#include "FrameFixedCost.h"
#include "MedicalTestUtilities.h"

#include <cmath>
#include <cstddef>
#include <limits>

namespace
{
using medical_test::Check;

bool Near(double value, double expected)
{
  return std::fabs(value - expected) <= 1e-12;
}
} // namespace

int main()
{
  using mediso::FrameFixedCost;

  // Nothing observed: no fixed cost, the whole budget left.
  {
    FrameFixedCost cost;
    Check(cost.Seconds() == 0.0 && cost.GetNumberOfFrames() == 0, "no frames: no fixed cost");
    Check(cost.BudgetLeft(0.1) == 0.1, "no frames: the whole budget is left");
  }

  // Steady frames: the window's seconds less the representation's.
  {
    FrameFixedCost cost;
    for (int frame = 0; frame < 20; ++frame)
    {
      // The representation's own time varies (levels switch); the rest does not.
      cost.Observe(0.010 + 0.005 * (frame % 4), 0.005 * (frame % 4));
    }
    Check(Near(cost.Seconds(), 0.010), "the fixed cost is the window's frame less the drawing");
    Check(Near(cost.BudgetLeft(0.1), 0.090), "the budget left is the budget less the fixed cost");
    Check(cost.BudgetLeft(0.005) == 0.0, "a fixed cost over the budget leaves none, not less");
    Check(cost.GetNumberOfFrames() == 20, "every frame is counted");
  }

  // The first frame (a window created, programs compiled outside the
  // representation) and a later stall decide nothing once there are more.
  {
    FrameFixedCost cost;
    cost.Observe(2.0, 0.05);
    Check(Near(cost.Seconds(), 1.95), "one frame: its difference");
    cost.Observe(0.06, 0.05);
    Check(Near(cost.Seconds(), 0.01), "two frames: the lower one (the lower median)");
    for (int frame = 0; frame < 5; ++frame)
    {
      cost.Observe(0.06, 0.05);
    }
    cost.Observe(0.9, 0.05); // a stall
    Check(Near(cost.Seconds(), 0.01), "a stalled frame does not move the median");
  }

  // A lasting change (another prop, a post-process pass) is followed once it
  // is most of the history, and not before.
  {
    FrameFixedCost cost;
    for (std::size_t frame = 0; frame < FrameFixedCost::HistoryLength; ++frame)
    {
      cost.Observe(0.03, 0.02);
    }
    std::size_t followed = 0;
    for (std::size_t frame = 1; frame <= FrameFixedCost::HistoryLength; ++frame)
    {
      cost.Observe(0.07, 0.02);
      if (followed == 0 && Near(cost.Seconds(), 0.05))
      {
        followed = frame;
      }
      if (frame < FrameFixedCost::HistoryLength / 2 + 1)
      {
        Check(Near(cost.Seconds(), 0.01), "a change held by fewer than half the frames waits");
      }
    }
    Check(followed == FrameFixedCost::HistoryLength / 2 + 1,
      "a lasting change is followed once it holds most of the frames");
  }

  // Bad input: never observed, never NaN; a window faster than the drawing
  // (clocks of different resolution) counts as no fixed cost.
  {
    FrameFixedCost cost;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    cost.Observe(nan, 0.01);
    cost.Observe(0.02, nan);
    cost.Observe(inf, 0.01);
    cost.Observe(-0.02, 0.01);
    cost.Observe(0.02, -0.01);
    Check(cost.GetNumberOfFrames() == 0 && cost.Seconds() == 0.0,
      "non-finite or negative times are not observed");
    cost.Observe(0.01, 0.02);
    Check(cost.GetNumberOfFrames() == 1 && cost.Seconds() == 0.0,
      "a window faster than the drawing costs nothing, not less");
    Check(cost.BudgetLeft(inf) == inf, "an unbounded budget stays unbounded");
    cost.Observe(0.5, 0.0);
    cost.Observe(0.5, 0.0);
    cost.Reset();
    Check(cost.GetNumberOfFrames() == 0 && cost.Seconds() == 0.0, "Reset forgets every frame");
  }

  return medical_test::Finish("TestFrameFixedCostCore passed");
}
