#include "posefair/core/slerped_measurements.hpp"

#include "posefair/core/so3.hpp"

#include <algorithm>
#include <cmath>

namespace posefair {

void SlerpedMeasurements::reset() {
  have_ = have_step_ = have_line_ = kinked_ = have_knot_ = have_anchor_ = false;
  interval_ = 0.0;
  run_ = 0;
  runs_.break_off();
}

bool SlerpedMeasurements::knot(const LinePoint& before, const LinePoint& after, SlerpKnot& at, bool& sharp) const {
  // Both lines are geodesics, the first before·exp(τ·ω_a), the second after·exp((τ − Δt)·ω_b);
  // the positions lines. Where they meet, e(τ) = log of the one's inverse times the other is zero
  // (and the positions' difference); de/dτ = ω_b − ω_a to first order in the step between them, so
  // Newton's step from τ = 0 finds τ, a second one to rounding, and what is left of e across
  // that direction says whether they meet at all. τ from rotation and position by least squares.
  const double span = after.time - before.time;
  const Vec3 turn = before.rate - after.rate, shift = before.velocity - after.velocity;
  const double denominator = turn.squaredNorm() + shift.squaredNorm();
  if (!(denominator > 0.0)) return false;  // parallel: no kink between them
  double tau = 0.0;
  Vec3 e, ep;
  for (int newton = 0; newton < 3; ++newton) {
    e = so3::log((before.orientation * so3::exp(tau * before.rate)).conjugate() * after.orientation *
                 so3::exp((tau - span) * after.rate));
    ep = after.position + (tau - span) * after.velocity - before.position - tau * before.velocity;
    if (newton < 2) tau += (turn.dot(e) + shift.dot(ep)) / denominator;
  }
  if (tau < -0.05 * span || tau > 1.05 * span) return false;  // (a knot on a sample, to rounding)
  const double along = (turn.dot(e) + shift.dot(ep)) / denominator;
  const double step = so3::log(before.orientation.conjugate() * after.orientation).norm();
  if ((e - along * turn).norm() > kContinuesWithin + kContinuesPer * step ||
      (ep - along * shift).norm() > kContinuesWithin + kContinuesPer * (after.position - before.position).norm())
    return false;  // the lines pass each other: no measurement joins them
  // Where the kink is within what rounding allows of a straight line (a clean stream whose
  // measurement fell near a sample), the time is not known to better than that.
  sharp = (kContinuesWithin + kContinuesPer * step) <= kSharpKnot * span * std::sqrt(denominator);
  const double t = std::clamp(tau, 0.0, span);
  at.time = before.time + t;
  at.orientation = (before.orientation * so3::exp(t * before.rate)).normalized();
  at.position = before.position + t * before.velocity;
  return true;
}

void SlerpedMeasurements::rate_of(LinePoint& p) {
  if (p.rated) return;
  p.rate = so3::log(p.step) / p.step_dt;
  p.rated = true;
}

bool SlerpedMeasurements::note(const Sample& s, SlerpKnot& next) {
  if ((s.flags & (kHasGyro | kHasAccel | kHasMag | kNoOrientation)) != 0) {
    reset();  // each sample measured anew
    return false;
  }
  const bool positions = s.has_position();
  LinePoint p{s.time, s.orientation, positions ? s.position : Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  const bool finite = std::isfinite(s.time) && s.orientation.coeffs().allFinite() && p.position.allFinite();
  if (!have_ || !finite || !(s.time > last_.time) || positions != positions_) {
    // A first sample, one the gate drops, or positions come or gone: lines start again.
    have_step_ = have_line_ = kinked_ = false;
    have_ = finite;
    positions_ = positions;
    last_ = p;
    return false;
  }
  const double dt = s.time - last_.time;
  p.step = last_.orientation.conjugate() * s.orientation;
  p.step_dt = dt;
  p.chord = (p.step.w() < 0.0 ? Vec3(-p.step.vec()) : Vec3(p.step.vec())) / dt;
  p.velocity = (p.position - last_.position) / dt;
  // The step's vector part (sin of half its angle, per second) first, which costs no log: two that
  // differ by twice the rounding allowed have logs that differ by more than it (to second order in
  // the step). Most steps of a measured stream end there; the rest are compared exactly.
  bool continues = false;
  if (have_step_ && ((p.chord - last_.chord) * dt).norm() <= 2.0 * (kContinuesWithin + kContinuesPer * p.chord.norm() * dt)) {
    rate_of(p);
    rate_of(last_);
    continues = ((p.rate - last_.rate) * dt).norm() <= kContinuesWithin + kContinuesPer * p.rate.norm() * dt &&
                ((p.velocity - last_.velocity) * dt).norm() <= kContinuesWithin + kContinuesPer * p.velocity.norm() * dt;
  }
  have_step_ = true;
  run_ = std::min(run_ + 1, kLongestRun);
  runs_.check_open_run(run_);  // no kink for far longer than the runs before: no longer slerped
  bool found = false;
  if (!continues && slerped() && have_anchor_ && !anchor_used_ && s.time >= anchor_.time + kMinPastKnot * dt &&
      s.time < anchor_.time + interval_) {
    // The first sample past the measurement expected at the anchor, off the line before: it is on
    // the slerp from that measurement to the next, which is thus known at once (the same the line's
    // confirmation finds, two samples later).
    const double f = interval_ / (s.time - anchor_.time);
    next.time = anchor_.time + interval_;
    next.orientation = (anchor_.orientation * so3::exp(f * so3::log(anchor_.orientation.conjugate() * s.orientation))).normalized();
    next.position = anchor_.position + f * (p.position - anchor_.position);
    anchor_used_ = found = true;
  }
  if (continues) {
    if (have_line_ && kinked_) {
      // A new line after a kink: the measurement where it meets the line before.
      LinePoint first = after_;
      first.rate = p.rate;
      first.velocity = p.velocity;
      SlerpKnot at;
      bool sharp = false;
      if (knot(line_, first, at, sharp)) {
        // A knot whose time is not sharp is where a measurement was expected (the line's value
        // there is as good as any), and does not move the interval. A kink within rounding of
        // none is not seen (a clean stream, now and then): the interval from the knot before is
        // then a few of the source's.
        if (!sharp && have_anchor_)
          at.time = anchor_.time + std::round((at.time - anchor_.time) / interval_) * interval_;
        if (have_knot_) {  // a run from knot to knot
          const double interval = at.time - knot_time_;
          const double intervals = interval_ > 0.0 ? std::max(1.0, std::round(interval / interval_)) : 1.0;
          if (interval_ == 0.0)
            interval_ = interval;
          else if (sharp && std::abs(interval - intervals * interval_) <= 0.25 * interval_)
            interval_ += kIntervalWeight * (interval / intervals - interval_);
          runs_.end_run(run_);
        }
        have_knot_ = true;
        knot_time_ = at.time;
        if (slerped()) {
          // The next measurement: on this line, one source interval after the one it starts at;
          // found already where the line's first sample was past its anchor (above). The anchor of
          // the next line's first sample.
          const double ahead = at.time + interval_ - s.time;
          anchor_.time = at.time + interval_;
          anchor_.orientation = (s.orientation * so3::exp(ahead * p.rate)).normalized();
          anchor_.position = p.position + ahead * p.velocity;
          if (!(have_anchor_ && anchor_used_)) {
            next = anchor_;
            found = true;
          }
          have_anchor_ = true;
          anchor_used_ = false;
        }
      } else {
        runs_.break_off();
        have_knot_ = have_anchor_ = false;
        interval_ = 0.0;
      }
      run_ = 0;
    }
    have_line_ = true;
    kinked_ = false;
    line_ = p;
  } else if (have_line_ && !kinked_) {
    kinked_ = true;  // the line ends at line_; p is the first sample after it
    after_ = p;
  }
  last_ = p;
  return found;
}

}  // namespace posefair
