#pragma once
// How much to smooth, estimated from the stream itself (the engine's default).
//
// The window smoother with weight μ trades noise for lag: its emitted value has noise variance
// σ²·G(μ) and, where the motion's m-th difference is d, a bias d·B(μ) (smoother_rows.hpp). Both
// G and B are known exactly for every candidate μ; what the stream must supply is σ² and d²:
//   noise σ²: from the (m+2)-th differences of the measurements, which smooth motion hardly
//     reaches and white noise fills with variance C(2m+4, m+2)·σ² per component. Robustly:
//     the median of their length (a χ with 3 degrees of freedom), tracked in log space, so
//     that outliers and short bursts of fast motion do not move it. The same from differences
//     three orders higher, where the window holds them; the smaller of the two is the noise
//     (motion fills the two orders unequally, white noise equally).
//   motion d²: the m-th derivative of a local polynomial fit (Savitzky–Golay, degree m, at
//     the centre of a short span), squared, averaged over a short time, minus the noise the
//     fit lets through (σ² times the sum of its squared weights, known exactly). Motion
//     below that noise cannot be told from none, so the estimate never goes below it: a
//     stream that only seems still is not smoothed without limit. The same fit over the whole
//     window tells a slow motion from none much more closely, and lowers that floor to what it
//     sees. A fit over half the span adds the motion's fast part (a shake) where it stands clear
//     of its own noise.
//   rest: a stream whose slope over the whole window is within its noise too is at rest (a
//     tracker put down, a head held still); after a motion has stopped, the slope over the
//     samples since, so that a rest is not put off until the motion has left the window. Then
//     the floor is dropped, and the motion counts
//     only where the fit sees it stand out of its noise: a still stream is smoothed as hard
//     as the window allows, a vibration (which a line through the window averages away but the
//     fit sees) is not. A motion starting, from rest or faster than the motion before, is taken
//     at once, not averaged in.
// The chosen μ minimises the expected squared error σ²G(μ) + d²B(μ)², the balance One Euro
// strikes by hand with β: fast motion gets little smoothing (no lag, no clamping), slow motion
// a lot. Every input is per sample; the time constants are in seconds, so streams of any rate
// behave alike. No allocation after construction.
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "posefair/core/repeated_exp.hpp"
#include "posefair/core/smoother_rows.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

// Valid ranges (validate(WindowConfig), the daemon's keys): time constants in (0, 600] s,
// the margin in (0, 100], the rest threshold in [0, 100].
inline constexpr double kMaxAdaptationTime = 600.0;
inline constexpr double kMaxMotionMargin = 100.0;
inline constexpr double kMaxRestThreshold = 100.0;

struct AdaptationSettings {
  double noise_time_s = 2.0;   // how fast the noise estimate follows a change of noise
  double motion_time_s = 0.1;  // how fast the motion estimate follows the motion
  double motion_span_s = 0.25; // span of the local fit that measures the motion
  // The motion counts this many times in the expected error. A fit over motion_span_s sees
  // only the motion's slower part, and smoothing too hard costs lag that the output never
  // makes up, while smoothing too little costs only the noise it leaves: so err light.
  double motion_margin = 2.0;
  // Motion below the noise the fit lets through counts as that noise (a stream that only seems
  // still is not smoothed without limit). Off for a gyro-aided residual, which is still by
  // construction: there the fit's noise would pass for motion and cap the smoothing.
  bool motion_floor = true;
  // At rest when the mean square of the slope of a line through the whole window (averaged over
  // motion_time_s, as the motion) is below this many times what the noise alone puts there; at
  // rest the motion counts only above this many times the fit's noise, and the floor is dropped;
  // it is at rest until twice this (MotionNoiseEstimator::kRestLeaveFactor).
  // Under noise alone both mean squares are once that noise. 0: never at rest (the floor always
  // holds). Needs the floor: a gyro-aided residual has none to drop.
  double rest_threshold = 2.0;
  // At rest, with no motion seen, the output is a line through every sample since the stream
  // came to rest, older samples weighing e^(−age/rest_memory_s), while it stays straight
  // (rest_line.hpp): a still pose averaged over seconds, not the window's half second.
  // 0: the window's heaviest smoothing at rest.
  double rest_memory_s = 1.0;
  // At lag 0, the noise estimate is checked by how well smoothings predict the next measurement,
  // and scaled down where a lighter one predicts it better (prediction_check.hpp).
  bool prediction_check = true;
};

// A difference D^kθ the noise estimate reads: its weights on the newest k differences ζ, and
// σ per unit of the median of its length under white noise.
struct NoiseDifference {
  int order = 0;
  std::array<double, 8> weights{};  // k ≤ m + 2 + MotionNoiseEstimator::kNoiseOrderAbove = 8
  double sigma_per_median = 0.0;
  double var_per_square = 0.0;  // σ² per unit of the mean square of its length under white noise
};

// Noise and motion of one channel (rotation or position), from its differences ζ.
class MotionNoiseEstimator {
 public:
  MotionNoiseEstimator(int capacity, int order);

  // Sets the fit's span for this rate (motion_span_s, at least order + 1 samples, at most
  // capacity) and the rest test's line through `window` samples (the window's W, at most
  // capacity), and forgets nothing else.
  void configure(double rate_hz, const AdaptationSettings& settings, int window);

  // After a new sample: zeta holds the window's n−1 differences, newest last; dt is the
  // newest step (seconds). Differences across a window restart are never used. True when the
  // motion estimate was refreshed or ready() changed (a choice of level made from the estimates
  // before stays as good until then: the noise estimate moves by a step of dt/noise_time_s).
  // line_zeta, when as long as zeta: the same differences on a chart, which the rest test's
  // line is fitted to instead (FairingWindow gives those of a rotation at rest: summed, the
  // increments ζ carry second-order terms that walk under heavy noise).
  // measured: how many of the newest samples were measured; the samples before them include one
  // the window stood in for (FairingWindow::stand_in), and no difference that reaches it goes into
  // the noise estimate.
  bool update(std::span<const Vec3> zeta, double dt, std::span<const Vec3> line_zeta = {},
              int measured = std::numeric_limits<int>::max());
  static constexpr double kMotionRefreshes = 25.0;  // motion fits per motion_time_s, at most
  // A stream at rest stays at rest until the line's mean square is this many times the
  // threshold. The window's slope is correlated over the whole window, so under noise alone a
  // single threshold is crossed about once a second, and each crossing switches the smoothing
  // between its heaviest level and a few Hz: a visible twitch in a still pose. A real motion
  // puts the slope far above either.
  static constexpr double kRestLeaveFactor = 2.0;
  // The slope goes into its average at most this many times the slope that leaves rest. The
  // average has only to say whether the slope is under the threshold; a turn puts it 10⁴–10⁵
  // times over, and the average then took 1 s or more after the turn had left the window to
  // come down (a time constant per factor e): a rest was seen a second after the turn. Capped,
  // it comes down to the threshold in 0.28 s. At 4 the quality benchmark's rests set gained
  // 3.5% in error instead of 3.1%, but rests were taken while a turn still crept to its end, and
  // the rest departure rule emitted more of its samples as measured: the jitter of quick turns
  // (`posefair bench streams`) rose by up to 22%, against 4% at 8.
  static constexpr double kRestSlopeCap = 8.0;
  // After the stop rule (kMotionStopFactor) the rest test's line spans only the samples clear of
  // the motion (the fit's span and the samples since), at least this many, until the window's
  // line is clear too: the rest was seen no sooner than the motion had left the window (0.5 s),
  // 0.8–0.9 s after a turn, and is now seen about 0.25 s after it. The rest line begins from
  // those samples, and the level chosen at rest still weighs the drag of rows that reach back
  // into the motion (stopped_motion): without that the heaviest level dragged each turn into the
  // rest after it (quick turns of `posefair bench streams` from 11% more error to 300 times it).
  // Never fewer than the fit's span either (at 10 Hz then none: the window holds 8; a rest test
  // on the fit's 3 samples there read TUM's handheld camera as still, docs/engine.md "At rest").
  // 16 and 32 gained less.
  static constexpr int kRestLineMinSamples = 8;
  // At rest, the motion's average counts (over rest_threshold times the fit's noise) only while
  // a fit stands clear of its noise too: the newest this many times over it (a motion starting),
  // or one of the last half to whole span kRestOnsetFactor times (a vibration, whose fit passes
  // through zero twice a period). The average of fits a few samples apart, which share most of
  // their samples, crossed the threshold by chance under noise alone 12 to 33 times a minute at
  // 10 Hz to 1 kHz, and each time the still pose went from the rest line to the window's few Hz
  // at once: a twitch, and 1.4 to 1.8 times One Euro's error on a still stream (mincutoff
  // 0.25 Hz). A motion starting puts its fits far over both: quick turns out of rest moved by 1%
  // at most (`posefair bench streams`). The newest fit alone lost a vibration at rest
  // (`Adaptation.AVibrationIsNotTakenForRest`); the span's largest fit alone at 8 took turns
  // under heavy noise a sample later (+3.4% at 30 Hz), and at 6 kept less of the gain at rest
  // at 120 Hz and up. The average alone over twice the threshold (4 times the noise) also saw
  // turns start a sample later, and lost up to 7% on them.
  static constexpr double kRestMotionFitFactor = 6.0;
  // At rest, a fit this many times over its noise, twice running and growing, is a motion
  // starting: the motion estimate takes it at once instead of averaging it in.
  static constexpr double kRestOnsetFactor = 8.0;
  // After a clear motion, the long fit and both half fits within this many times their noise,
  // twice running, are a motion stopping: the averages drop to the noise at once. Noise alone
  // puts a fit there 89% of the time. At 1 the rule fired by chance (all three fits within the
  // noise twice running, about 1 in 25 after a turn had stopped) and took half the gain on the
  // rests set (1.3% instead of 2.3%); at 3 a shake and a walk at 250 Hz and 1 kHz lost 1–2%.
  static constexpr double kMotionStopFactor = 2.0;
  // The long fit spans 0.25 s: a turn's stop was seen no sooner than that after its end, and the
  // first 0.25 s after each turn held a fifth of the quality benchmark's error on its rests set
  // and as much of its jitter, smoothed as lightly as the turn. The newest half span's fit within
  // kMotionStopFactor times its noise and its line's slope within this many times the slope's
  // noise (the pose no longer moves), twice running after a clear motion, are a stop too (about
  // 0.1 s after a turn at 100 Hz), with only that half span clear of the motion; until the long
  // span is clear, the half's fit stands for the long one. At 2 a 5 Hz vibration under noise was
  // taken for stops (1.5% more error, `Adaptation.AVibrationIsNotTakenForRest`). docs/engine.md,
  // "A stop seen on the newest half span".
  static constexpr double kStillSlopeFactor = 1.0;
  // A smoothing level's correction (output − measurement) that stands this many times over what
  // the noise alone puts in it (its mean square against σ² times the level's correction gain) is
  // bias: motion the estimate missed. The m-th difference that bias implies through the level's
  // bias per unit counts as motion, kept for motion_time_s. After a turn stops, the stop rule
  // drops the motion to the noise while the turn is still in the window, and a heavy level then
  // drags the pose after the turn: on a clean stream (noise 0.0001 rad) 0.003–0.006 rad off, six
  // times raw's error. So high because the implied difference holds for the level that made the
  // correction and overstates it for lighter ones, whose rows do not reach back to the turn: at
  // 32 quick turns under noise 0.01 at 30 Hz lost 0.9%, at 128 nothing did (docs/engine.md,
  // "A correction the noise does not explain").
  static constexpr double kBiasFactor = 128.0;
  // Moving, a fit whose excess over its noise is this many times the motion's (or the noise's,
  // if larger), twice running and growing, is a faster motion starting (a head turned quickly):
  // taken at once too. Averaged in, a 60° turn in 0.1–0.15 s was over before the average saw
  // it, and was smoothed as hard as the slow motion before it.
  static constexpr double kMotionOnsetFactor = 4.0;
  // At either onset the size taken is the larger of the fit's and the newest half span's (of the
  // running median of three), the latter where it stands this many times over its noise: the
  // long fit sees its newest end dimly. One fit, not an average as kFastMotionFactor's, so the
  // rest onset's margin (at 4, a stream of 1 kHz with noise of 0.05 rad lost 0.35%).
  static constexpr double kOnsetSizeFactor = 8.0;
  // The fit over motion_span_s averages away a fast motion (a 6–8 Hz shake, which a quadratic
  // over 0.25 s cannot follow), and the stream was then smoothed below the shake: two to five
  // times raw's error. The same fit over half the span, on the newest half and on the half before
  // it, sees it; the smaller of the two (an outlier is in one half only, a shake in both),
  // averaged as the motion, counts where it stands this many times over its noise.
  static constexpr double kFastMotionFactor = 4.0;
  // The noise estimate also reads the differences this many orders above m + 2, and takes the
  // smaller σ² of the two: white noise fills every order alike, while a motion's share falls
  // from one order to the next wherever it lies below 0.4 of the rate (a 5–9 Hz tremor at 30
  // Hz, a handheld camera) and grows only nearer Nyquist. Read at m + 2 alone, a 6–7 Hz tremor
  // of 0.02 rad at 30 Hz under noise of 0.0007 rad per axis read as 5.7 times that noise.
  static constexpr int kNoiseOrderAbove = 3;
  // ... its σ counted at this many times its value: two estimates of one white noise differ by
  // their sampling spread, and the smaller of the two is biased low (taken plainly, still
  // streams, whose rest test weighs the slope against σ, lost 2–17% of their gain).
  static constexpr double kNoiseOrderMargin = 1.1;
  // A noise that changes its level (a tracker losing sight of a marker, a camera in low light)
  // puts every length on one side of the tracked median, and the median's fixed step follows it
  // by a factor e^(1/4) a second: six times the noise took 7 s. After this many lengths in a row
  // on one side, or kNoiseFarSamples in a row more than kNoiseFarFactor times above or below it,
  // the step doubles with each further one, up to kNoiseRunStepCap (in log σ per sample), until
  // the run ends. Under a steady noise the lengths of overlapping differences run together: with
  // runs of 8 or 16 the estimate wandered, still streams left rest by chance and lost up to 78%
  // (8) of their gain; with far runs of 4 or 5, up to 4%. With these, nothing in `posefair bench
  // streams` or the quality benchmark moved by more than 1% but three streams at 1 kHz
  // (docs/engine.md, "A noise that changes its level").
  static constexpr int kNoiseRunSamples = 32;
  static constexpr int kNoiseFarSamples = 6;
  static constexpr double kNoiseFarFactor = 2.0;
  static constexpr double kNoiseRunStepCap = 0.1;
  // Even so the median follows a risen noise only within a second, and at rest each burst of
  // noise (five times the noise for a second) was taken for a motion: its first samples stood
  // over the rest onset and the rest line's slope over the leave threshold, and the stream was
  // smoothed at the motion's few Hz until the rest was seen again (a still tracker kept 0.62 of
  // raw's error at 60 Hz, where One Euro at 0.25 Hz keeps 0.24). Where most of the newest
  // kRecentNoiseSamples lengths, at both orders, stand kNoiseFarFactor times above their median,
  // the noise has risen, until most no longer stand above it (the median catching up is not the
  // burst's end: without this, the rest was left while it did, 0.37 instead of 0.27 of raw's
  // error on a still stream with bursts at 60 Hz), and their mean square (a running mean of
  // weight kRecentNoiseWeight) says by how much: a rest is judged against that (rest_noise_variance). A sample off the rest
  // line is still judged against the median's, and two in a row on one side go out as measured
  // where their mean stands beyond the risen noise: a motion starting in a burst would otherwise
  // go out at the still pose until each sample stood beyond it (docs/engine.md, "A noise burst
  // at rest").
  static constexpr int kRecentNoiseSamples = 9;
  // An order's median has caught up with a noise that rose where it stands this many times over
  // the tracked σ² (recent_noise_var).
  static constexpr double kCaughtUpFactor = 2.0;
  static_assert(kRecentNoiseSamples < 32, "the newest lengths are bits of a std::uint32_t");
  static constexpr double kRecentNoiseWeight = 0.2;
  // The newest lengths' mean square follows a burst's onset within a few samples, but as quickly
  // dips by chance within it (to a third of the burst's level, on the high orders' correlated
  // lengths), and the rest judged against that dip was left: a still stream with bursts at 60 Hz
  // was smoothed at a few Hz for a fraction of each burst. While the noise has risen, an order's
  // σ² is the larger of that mean and a slower one's (weight kSteadyNoiseWeight, about 20 lengths),
  // which holds the burst's level.
  static constexpr double kSteadyNoiseWeight = 0.05;

  // What the estimator has learnt from the stream (its weights aside, which configure() sets):
  // small and copyable, so that a window can put it back as it was before a sample it took
  // back (fairing_window.hpp, outliers).
  struct Estimates {
    // Noise: the medians of ‖D^kθ‖ at k = m + 2 and at the higher order, each exact over its
    // first values, then tracked; σ² from the smaller.
    struct LengthMedian {
      std::array<double, 15> first_lengths{};
      int count = 0;
      double median = 1.0;  // tracked by factors e^(±step): a step in log space
      int run = 0;  // lengths in a row above the median (> 0) or below it (< 0)
      int far_run = 0;  // lengths in a row kNoiseFarFactor times above it (> 0) or below (< 0)
      std::uint32_t recent_far = 0;    // bit i: the (i + 1)-th newest length stood kNoiseFarFactor times above it
      std::uint32_t recent_above = 0;  // bit i: ... stood above it
      double recent_square = 0.0;      // the lengths' squares, a running mean (kRecentNoiseWeight)
      double steady_square = 0.0;      // the same, a slower running mean (kSteadyNoiseWeight)
      bool risen = false;              // the noise has risen lately (kRecentNoiseSamples)
      bool settled() const { return count >= static_cast<int>(first_lengths.size()); }
    };
    LengthMedian low, high;
    double noise_var = 0.0;
    double rest_noise_var = 0.0;  // σ² a rest is judged against (rest_noise_variance)
    // Motion: the fit's mean square, the stream time since it was last taken, and d².
    double mean_square = 0.0;
    bool motion_ready = false;
    double motion_pending_s = 0.0;
    double motion_var = 0.0;
    // The mean squares of the fast part's fit (the smaller of two neighbouring half spans), the
    // slow part's (over the window) and the rest test's line.
    double short_mean_square = 0.0;
    double window_mean_square = 0.0;
    bool window_ready = false;
    double line_mean_square = 0.0;
    bool line_ready = false;
    // The rest test's line is the one through this many samples clear of a motion that stopped
    // (0: the window's line).
    int line_clear = 0;
    double bias_motion = 0.0;  // d² implied by corrections over kBiasFactor times their noise, decaying
    double bias_last = 0.0;    // the last correction's implied d² (0: within that)
    bool at_rest = false;
    // The last fit at rest read a motion, and the one before it (motion_read_twice_at_rest).
    bool rest_motion_read = false, rest_motion_read_before = false;
    bool onset_over = false;  // the last fit stood over the onset threshold
    double onset_last = 0.0;  // the last fit's mean square
    bool stop_last = false;   // the last fit stood within its noise after a clear motion
    // The motion the stop rule dropped (d², 0: none) and the samples taken since: it is still in
    // the window's older samples until the window has slid past it.
    double stopped_motion = 0.0;
    int samples_since_stop = 0;
    int stop_clear = 0;  // the newest samples clear of it when it stopped: the fit's span or half span
    // The largest fit of the last half span and of the half span before it (in stream time), and
    // the time the newer half has run: the largest fit of the last half to whole span.
    double peak = 0.0, peak_before = 0.0, peak_s = 0.0;
  };
  // What the level in use corrected at the emitted sample: the correction's mean square per
  // component, the level's correction gain and bias per unit m-th difference (EmissionRow);
  // mean_square 0 and bias 0 where nothing was corrected. The motion follows it (kBiasFactor).
  void note_correction(double mean_square, double correction_gain, double bias, double dt);
  const Estimates& estimates() const { return e_; }
  void restore(const Estimates& e) { e_ = e; }

  bool ready() const { return e_.low.count > 0 && e_.motion_ready; }
  // A motion that stopped while still in the window: its d² (per component, per sample^(2m)) and
  // how many of the newest samples are clear of it (samples_clear_of_stop). At rest too (only
  // while the rest test's line was the short one until a stop could be seen on the half span:
  // then a rest begun on the window's line had the motion clear of the window's rows); none once
  // `window` samples are clear. Of two stops while one is in the window, the larger d². The level
  // chosen weighs the drag each row puts on the still pose (tail_bias in smoother_rows.hpp).
  struct StoppedMotion {
    double motion_var = 0.0;
    int clear = 0;
  };
  StoppedMotion stopped_motion(int window) const;
  bool at_rest() const { return e_.at_rest; }
  // The last two fits at rest read a motion (twice running, as the onset rule takes one): a single
  // fit reads the noise as one now and then.
  bool motion_read_twice_at_rest() const { return e_.rest_motion_read && e_.rest_motion_read_before; }
  // How many of the newest samples the rest test's line spans: the window's, or after a motion
  // stopped those clear of it. A rest line begun now takes these.
  int rest_span() const { return e_.line_clear > 0 ? e_.line_clear : line_span_; }
  double noise_variance() const { return e_.noise_var; }    // σ², per component, per sample
  // σ² a rest is judged against: the noise's, or where it has risen lately, the newest samples'
  // (kRecentNoiseSamples).
  double rest_noise_variance() const { return std::max(e_.rest_noise_var, e_.noise_var); }
  double motion_variance() const { return e_.motion_var; }  // d², per component, per sample^(2m)
  int span() const { return span_; }

 private:
  // The newest samples clear of the motion the stop rule saw stop: the fit's span (or its newest
  // half, kStillSlopeFactor), within its noise when the rule fired, and the samples since.
  int samples_clear_of_stop() const { return e_.stop_clear - 1 + e_.samples_since_stop; }
  // Takes a length ‖D^kθ‖ into the tracker of its order's median.
  void update_median(Estimates::LengthMedian& m, double length, double dt);
  // The least motion assumed while moving: the noise the fit lets through, or less where the
  // window's fit sees the motion is smaller.
  double motion_floor(double fit_noise) const;
  // σ² of the newest samples where the noise has risen lately (kRecentNoiseSamples), or 0.
  double recent_noise_var() const;
  // The fit over the newest half span of the samples' running median of three, its mean square.
  double newest_half_fit_of_medians(std::span<const Vec3> zeta) const;

  int order_;
  int capacity_;
  NoiseDifference low_;   // D^kθ at k = m + 2
  NoiseDifference high_;  // at the higher order (order 0: none, the window is too short)
  AdaptationSettings settings_;
  int span_ = 0;
  std::vector<double> fit_;      // weights on the span's span−1 differences
  double fit_noise_gain_ = 0.0;  // Σ of the fit's squared weights on θ
  double peak_half_s_ = 0.0;     // half the fit's span (s): the blocks of Estimates::peak
  // Factors per step: Estimates::bias_motion's, the motion averages' between fits, and the
  // medians' up and down (update_median).
  RepeatedExp bias_decay_, motion_decay_, median_up_, median_down_;
  // The motion's fast part: the same fit over half the span (0: none), and its noise gain.
  int short_span_ = 0;
  std::vector<double> short_fit_;
  double short_fit_noise_gain_ = 0.0;
  // The motion's slow part: the same fit over the whole window (line_span_ samples; none where
  // that spans more than twice motion_span_s), and its noise gain.
  std::vector<double> window_fit_;
  double window_fit_noise_gain_ = 0.0;
  // Rest: a line through the newest line_span_ samples, and Σ of its slope's squared weights on θ.
  int line_span_ = 0;
  double line_noise_gain_ = 0.0;
  // The weights of the lines through line_span_ and short_span_ samples (newest_line_slope),
  // tabled: both are taken at every motion fit.
  std::vector<double> line_weights_, short_line_weights_;
  Estimates e_;
};

// The smoothing level (a real index into rows, ordered from least to most smoothing) with the
// smallest expected squared error σ²·G + d²·B² (+ e²·T², below). A fractional level l + f emits the blend
// (1 − f)·u_l + f·u_{l+1}, whose bias (1 − f)B_l + f·B_{l+1} and noise gain
// (1 − f)²G_l + 2f(1 − f)G_{l,l+1} + f²G_{l+1} are exact, so f is chosen exactly on both sides
// of the best whole level. shared_gain[l] = G_{l,l+1} (shared_noise_gain of rows l and l + 1).
// tail[l], where given: row l's tail_bias for a motion that stopped (MotionNoiseEstimator::
// stopped_motion), whose d² is tail_var; its drag e²·T² adds to the error as the bias does.
double best_level(std::span<const EmissionRow> rows, std::span<const double> shared_gain, int count, double noise_var,
                  double motion_var, std::span<const double> tail = {}, double tail_var = 0.0);

}  // namespace posefair
