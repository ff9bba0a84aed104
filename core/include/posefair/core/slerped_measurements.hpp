#pragma once
// A stream slerped from a slower source: each sample on the geodesic between two measurements.
//
// A log put on another clock, or a tracker's driver that interpolates its 60 Hz measurements to
// the 250 Hz a runtime reads, takes equal steps from one measurement toward the next (a slerp for
// the orientation, a line for the position). No sample of it is a measurement (each mixes two),
// and its noise is coloured: read at the stream's rate the engine finds almost none, and the
// samples predict each other, so it passed such a stream through (docs/engine.md, "Streams
// resampled from a lower rate"). But the stream holds its measurements exactly: a run of equal
// steps is a geodesic, and two neighbouring runs meet at the measurement between them.
//
// So each step is compared with the one before: equal to rounding (kContinuesWithin, per unit
// of time: the samples need not be evenly spaced), it continues a line; two equal steps in a row
// after a change confirm a new line, which meets the line before at a knot: the measurement, at
// the time between the last sample of the line before and the first of the new one where the two
// meet. The next measurement is on the new line one source interval later (the mean of the
// intervals between knots): a slerped sample already moves toward it, so the engine fairs that
// one as soon as the stream shows it (the line confirmed, or before: the first sample past the
// measurement expected), and interpolates the samples between. Under little noise a kink is now
// and then within rounding of none: a knot whose time that leaves unsharp is put on the grid of
// the source's intervals, and an interval over several of them (a kink unseen) counts as several.
// A stream is taken as slerped only where its runs between confirmed lines come regularly
// (regular_runs.hpp) and average at least kMinSlerpRun samples (a source at a third of the rate
// or less: each run needs two equal steps after its kink), every knot lies between its two lines'
// samples and the two lines meet there to rounding. A measured stream never has equal steps but
// by rounding (a clean slow motion read fast: a run with no end, which is irregular), and exact
// repeats are repeated_measurements.hpp's (a line of no motion, whose knots do not meet).
// No allocation; O(1) per sample.
#include "posefair/core/regular_runs.hpp"
#include "posefair/core/sample.hpp"

namespace posefair {

inline constexpr double kMinSlerpRun = 3.0;

// A measurement the slerped stream holds: its time, orientation and position.
struct SlerpKnot {
  double time = 0.0;
  Quat orientation = Quat::Identity();
  Vec3 position = Vec3::Zero();
};

class SlerpedMeasurements {
 public:
  // Two steps are equal where they differ by at most this (rad of log, metres), plus kContinuesPer
  // of the step: a slerp recomputed from stored quaternions and times differs by rounding alone
  // (float32 components: about 1e-7; times stored to the microsecond: 2.5e-4 of a 4 ms step), a
  // measured stream by its noise (1e-4 or more).
  static constexpr double kContinuesWithin = 2e-6;
  static constexpr double kContinuesPer = 1e-3;
  // A sample this many of the stream's steps past the measurement expected (or more) finds the next
  // one: closer, the rounding of its slerp fraction would weigh too much.
  static constexpr double kMinPastKnot = 0.2;
  // A knot's time is sharp where the two lines part by the rounding allowed within this part of
  // the step between their samples.
  static constexpr double kSharpKnot = 0.05;
  // The running mean of the source's interval gives the newest interval this weight.
  static constexpr double kIntervalWeight = 0.125;

  // Notes a sample (before the gate). True where it confirms a new line and the stream is
  // slerped: `next` is the measurement at the line's end, one source interval after its start.
  bool note(const Sample& s, SlerpKnot& next);
  // Whether the stream is slerped from a slower source (above).
  bool slerped() const { return runs_.regular() && interval_ > 0.0; }

 private:
  struct LinePoint {
    double time = 0.0;
    Quat orientation = Quat::Identity();
    Vec3 position = Vec3::Zero();
    Vec3 rate = Vec3::Zero();      // of the orientation's log, per second (body frame), once rated
    Vec3 velocity = Vec3::Zero();  // of the position, per second
    Quat step = Quat::Identity();  // from the sample before, over step_dt
    double step_dt = 1.0;
    Vec3 chord = Vec3::Zero();     // the step's vector part, per second
    bool rated = false;
  };
  static void rate_of(LinePoint& p);  // its rate from its step, once
  void reset();
  // The knot where the line through `before` meets the line through `after` (the sample after it),
  // or false where they do not meet between the two.
  // sharp: its time is known to kSharpKnot of the step between them.
  bool knot(const LinePoint& before, const LinePoint& after, SlerpKnot& at, bool& sharp) const;

  bool have_ = false, have_step_ = false;
  bool positions_ = false;         // the samples have positions
  LinePoint last_;                 // the newest sample, with its step's rates
  bool have_line_ = false;         // a confirmed line, whose newest sample is line_
  LinePoint line_;
  bool kinked_ = false;            // a step since line_ left it: the sample after it is after_
  LinePoint after_;
  bool have_knot_ = false;
  double knot_time_ = 0.0;         // the newest knot's
  // The measurement expected next (on the newest confirmed line, an interval after its knot), and
  // whether the next measurement was found from it already.
  bool have_anchor_ = false, anchor_used_ = false;
  SlerpKnot anchor_;
  double interval_ = 0.0;          // the source's, a running mean (0: none yet)
  int run_ = 0;                    // samples since the last confirmed line
  RegularRuns runs_{kMinSlerpRun};
};

}  // namespace posefair
