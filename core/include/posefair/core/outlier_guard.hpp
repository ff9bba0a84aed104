#pragma once
// A lone outlier, or a short burst of them: a sample far from where the samples before it were
// going (an optical tracker's reflection taken for a marker for a frame or two, a value corrupted
// but still parsed).
// Smoothing cannot hide one: the window spreads it over its neighbours, and it breaks the rest
// test, so a still stream with 1% of its samples 0.2 rad off gets 75% more error than a fixed
// 1 Hz cutoff (docs/engine.md, "Outliers").
//
// The guard predicts each sample from a line through the few before it (least squares on the
// sum of their increments against their real times), and tracks the median of how far samples
// land from that prediction. A sample further than `threshold` times that median is held at the
// prediction if the sample before it was ordinary (within three times the median). A sudden motion
// mostly builds up over a sample or two, which puts the sample before it off the line already;
// and the sample after a held one tells an outlier from a motion's start or a jump that stays:
// after an outlier it lands near the line (or, in a burst of outliers, far from both the line and
// the line's step from the held one, and is held too, up to kMaxHeldRun in a row), after a start
// nearer the line's step from the held measurement than the line, and the held sample is
// released (taken back into the window as measured, and emitted so if the window's lag has not
// emitted it yet; the window's adaptation learns from it as if it had never been held). A released sample is a step in the line for the
// samples after it, and nothing new is held until it has left the line's points. So with a lag
// the guard costs a sudden motion nothing. At lag 0 a held sample
// is emitted before the next one comes, so the window emits it as measured and holds it only for
// the poses after it (fairing_window.hpp): a sudden motion costs nothing there either. The rest
// of a burst (continues_burst) is no motion's start, and goes out at the prediction.
// The median is the stream's own (its noise and how well its motion is predicted), so the
// threshold needs no units; below a small floor nothing is held (a still, quantised stream whose
// median is zero would otherwise hold every least bit it moves).
// One guard per channel: rotation (increments log(z_j⁻¹ z_{j+1})) and position (p_{j+1} − p_j).
// Fixed size, no allocation.
#include <array>

#include "posefair/core/so3.hpp"

namespace posefair {

// Points of the line the prediction comes from (the sample before plus its predecessors).
inline constexpr int kOutlierFitPoints = 6;
// Distances before the median is trusted: nothing is held before (a guard that started low
// would hold real samples; it starts at the largest of these and comes down).
inline constexpr int kOutlierWarmUp = 20;
// Below this distance from the prediction (rad of rotation angle, or position units) nothing is
// held: under any tracker's noise, and smaller than any outlier worth a held sample.
inline constexpr double kOutlierFloor = 1e-4;
// The most samples held in a row (a tracker glitching for a few frames, each sample thrown its
// own way); the sample after them is taken. Only the newest held sample can be released.
inline constexpr int kMaxHeldRun = 3;
// The largest threshold accepted (multiples of the median).
inline constexpr double kMaxOutlierThreshold = 1000.0;

class OutlierGuard {
 public:
  // threshold: multiples of the median of the prediction's error (WindowConfig's
  // outlier_threshold); 0 holds nothing.
  // scale: the increment's units per unit of distance (rotation: log gives half the angle, so
  // 0.5; position: 1).
  OutlierGuard(double threshold, double scale);

  enum class Verdict {
    Take,
    Hold,     // an outlier (alone, or in a burst): increment is replaced by the prediction
    Release,  // the sample before was held, but this one says a motion started: it lands nearer
              // the line's step from the held measurement than the line. Take the held sample
              // back as measured; increment is made relative to it.
  };
  // The sample `step` seconds after the previous one, `increment` from it (from the held
  // prediction, if the previous sample was held).
  Verdict check(double step, Vec3& increment);
  bool on() const { return threshold_ > 0.0; }
  // The sample just held follows a held one: the second or third of a burst. Not a motion's
  // start: a motion's next sample goes on from the held one as the line goes on, and releases it.
  bool continues_burst() const { return held_run_ >= 2; }
  // A new window: the line starts afresh (the median, the stream's own, carries on).
  void restart() {
    count_ = 0;
    ordinary_before_ = false;
    held_run_ = 0;
    settling_ = 0;
  }

 private:
  double threshold_;
  double scale_;
  // The newest kOutlierFitPoints − 1 steps and increments, a ring; count_ of them held.
  std::array<double, kOutlierFitPoints - 1> step_{};
  std::array<Vec3, kOutlierFitPoints - 1> increment_{};
  int head_ = 0;
  int count_ = 0;
  double median_ = 1.0;  // tracked by factors e^(±kRate): a step in log space
  int seen_ = 0;  // distances seen, up to kOutlierWarmUp
  bool ordinary_before_ = false;  // the sample before landed within kOrdinary times the median
  Vec3 held_offset_ = Vec3::Zero();  // the newest held sample's measurement from the prediction
  int held_run_ = 0;   // samples held in a row, up to the newest checked (0: the sample before was not held)
  int settling_ = 0;   // samples until a released step has left the line's points (nothing new is held)
};

}  // namespace posefair
