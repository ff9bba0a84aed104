#pragma once
// The noise estimate checked against the stream's next measurement.
//
// The adaptation reads the noise from the stream's highest differences (smoothing_adaptation.hpp).
// A motion that fills them as noise does (a walk's wandering rate, a shake near Nyquist, a clean
// tracker's quick turns) reads as noise, and the level chosen then smooths real motion: a clean
// walk at 10 Hz had 6.4 times raw's error (docs/engine.md, "Checked by the next measurement").
// What the stream does show, whatever its noise, is how well a smoothing predicts the next
// measurement: the squared error of a prediction made from the samples before is the next sample's
// noise σ² (the same for every predictor, since that noise is independent of the past) plus the
// prediction's own error. So of two smoothings, the one that predicts the next measurement better
// is the better estimate of the motion, with no need to know σ² (the prediction error method of
// system identification).
//
// Candidates: the noise estimate scaled by kScaleStep^j, j = 0 … kCandidates − 1, each choosing its
// level as the adaptation does. For each sample the window predicts the next measurement with each
// candidate's level (rows one sample ahead); here the squared errors are averaged over kTime, and
// a candidate is taken where its mean error is below the unscaled one's by more than kSignificance
// standard errors (of the paired difference, sample by sample). Taken, it stays while it is still
// below on average. Only downward: white noise fills the highest differences whatever else does,
// so they do not read less noise than there is.
// Until it has evidence the lightest candidate goes out: a noise estimate no comparison has
// weighed may be motion (a clean walk at 10 Hz was smoothed to 6 times raw's error for the 1–2 s
// the first comparisons took), and passing the measurements through is never far from them. The
// evidence: kMinSamples comparisons (then the lightest stays while it predicts better on average),
// the lightest predicting worse by kSignificance standard errors (from kFirstSpread comparisons
// on), or a rest, where the highest differences hold the noise alone (note_rest).
// Small and copyable (the window puts it back with the adaptation after a held sample).
#include <array>
#include <span>

#include "posefair/core/so3.hpp"

namespace posefair {

class PredictionCheck {
 public:
  static constexpr int kCandidates = 6;
  static constexpr double kScaleStep = 0.25;  // down to 1/1024 of the noise variance: a 32nd of σ
  // The errors' averaging time. At 2 s a still stream's and quick turns' choice wandered more
  // (`posefair bench streams`, 2026-12-06: the same gains, one loss more); 4 s is 40 samples at 10 Hz.
  static constexpr double kTime = 4.0;
  static constexpr double kSignificance = 2.0;
  static constexpr int kMinSamples = 8;  // compared errors before a candidate can be taken
  static constexpr int kFirstSpread = 3;  // compared errors before the lightest can be let go as worse
  // Predictions made and compared per second, at most: at 1 kHz every 10th sample (400 in the
  // average over kTime), a third of the cost of every refresh of the levels.
  static constexpr double kChecksPerSecond = 100.0;

  // The noise variance's factor of candidate j (by products: a pow per candidate per check was
  // among the engine's costs; kScaleStep a power of two, they are exact).
  static constexpr double scale(int j) {
    double s = 1.0;
    for (int i = 0; i < j; ++i) s *= kScaleStep;
    return s;
  }

  // evaluations_per_second: how often note() is called on a steady stream (the rate, or less).
  // lightest_first: the lightest candidate until the estimate is weighed (above); false where the
  // lightest is not near the measurements (a horizon: it dead-reckons them, noise and all).
  void configure(double evaluations_per_second, bool lightest_first);
  // The squared errors of each candidate's prediction of the newest measurement, candidate 0's
  // first (per component).
  void note(std::span<const double, kCandidates> squared_errors);
  // The stream is at rest: its noise estimate is the noise alone.
  void note_rest() { s_.weighed = true; }
  // Forgets what it has compared (a new stream).
  void restart();

  int choice() const { return s_.weighed ? s_.choice : kCandidates - 1; }
  double scale() const { return scale(choice()); }

  // The predictions the window made for the next measurement, kept with what was compared.
  struct State {
    std::array<double, kCandidates> mean{};         // of (error_j − error_0)
    std::array<double, kCandidates> mean_square{};  // of (error_j − error_0)²
    double count = 0.0;                              // comparisons made (while under the averaging's length)
    int choice = 0;
    std::array<Vec3, kCandidates> prediction{};
    bool predicted = false;  // prediction holds one for the next sample
    double since_check_s = 0.0;  // stream time since the last predictions were made
    bool weighed = false;    // the noise estimate has evidence (before it, the lightest goes out)
  };
  State& state() { return s_; }
  const State& state() const { return s_; }

 private:
  double alpha_ = 0.0;  // the average's weight for one comparison
  bool lightest_first_ = true;
  State s_;
};

}  // namespace posefair
