#include "posefair/core/smoothing_adaptation.hpp"

#include "posefair/core/combinatorics.hpp"
#include "posefair/core/upper_median.hpp"
#include "posefair/core/weighted_vector_sum.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include <Eigen/Cholesky>

namespace posefair {
namespace {

// Median of the χ distribution with 3 degrees of freedom: the length of a 3-vector of unit
// normal components is below this half of the time.
constexpr double kChi3Median = 1.5381722;

// A sum Σ_i w_i θ_i over `span` samples whose weights sum to zero, as weights on the span's
// differences: Σ w_i θ_i = −Σ_j W_j ζ_j with W_j = Σ_{i≤j} w_i, written to out[0, span − 1).
// Returns Σ w_i², the sum's noise gain on θ.
template <class Weight>
double difference_weights(int span, Weight&& w, std::vector<double>& out) {
  double cumulative = 0.0, gain = 0.0;
  for (int i = 0; i < span; ++i) {
    const double wi = w(i);
    gain += wi * wi;
    cumulative += wi;
    if (i < span - 1) out[static_cast<std::size_t>(i)] = -cumulative;
  }
  return gain;
}

// The m-th derivative at the centre of a least-squares polynomial of degree m through `span`
// samples, as weights on their differences (difference_weights): w_i = m!·[(XᵀX)⁻¹Xᵀ]_{m,i},
// X_{iq} = (i − c)^q. At most 4×4 (m ≤ 3): fixed size, no heap. Returns the fit's noise gain.
double derivative_fit_weights(int span, int m, std::vector<double>& out) {
  const double c = 0.5 * (span - 1);
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  const int q = m + 1;
  for (int i = 0; i < span; ++i) {
    Eigen::Vector4d x = Eigen::Vector4d::Zero();
    for (int p = 0; p < q; ++p) x(p) = std::pow(i - c, p);
    normal += x * x.transpose();
  }
  for (int p = q; p < 4; ++p) normal(p, p) = 1.0;  // unused powers (m = 2)
  const Eigen::LDLT<Eigen::Matrix4d> ldlt(normal);
  Eigen::Vector4d unit = Eigen::Vector4d::Zero();
  unit(m) = 1.0;
  const Eigen::Vector4d a = ldlt.solve(unit);  // row m of (XᵀX)⁻¹
  const double m_factorial = factorial(m);
  return difference_weights(
      span,
      [&](int i) {
        double w = 0.0;
        for (int p = 0; p < q; ++p) w += a(p) * std::pow(i - c, p);
        return w * m_factorial;
      },
      out);
}

// The least-squares slope of a line through the newest `samples` samples (per sample), from
// their differences ζ (the last samples − 1 of zeta), and Σ(i − c)² over them: the slope's noise
// gain on θ is its inverse. The weights in closed form, (j + 1)(L − 1 − j)/(2·Sxx) on the j-th
// difference, summed as difference_weights would: after a stop the span changes from one call to
// the next, and one closed form serves it and the window's line.
struct LineSlope {
  Vec3 slope;
  double sxx;
};
// The weights' common divisor 2·Sxx is taken out: (j + 1)(L − 1 − j), exact integers.
double line_weight(int samples, int j) { return (j + 1.0) * (samples - 1.0 - j); }
void table_line_weights(int samples, std::vector<double>& out) {
  for (int j = 0; j + 1 < samples; ++j) out[static_cast<std::size_t>(j)] = line_weight(samples, j);
}
// `table`: the weights for `samples`, tabled, or empty.
LineSlope newest_line_slope(std::span<const Vec3> zeta, int samples, std::span<const double> table = {}) {
  const double l = samples, sxx = l * (l * l - 1.0) / 12.0;
  const std::span<const Vec3> differences = zeta.subspan(zeta.size() - static_cast<std::size_t>(samples - 1));
  const Vec3 v = table.empty() ? weighted_vector_sum(0, samples - 1, [&](int j) { return line_weight(samples, j); }, differences)
                               : weighted_vector_sum(0, samples - 1, [&](int j) { return table[static_cast<std::size_t>(j)]; }, differences);
  return {v / (2.0 * sxx), sxx};
}

// The componentwise median of three vectors.
Vec3 median_of_three(const Vec3& a, const Vec3& b, const Vec3& c) {
  return a.cwiseMin(b).cwiseMax(a.cwiseMax(b).cwiseMin(c));
}

// D^kθ at the newest sample, as D^{k−1} of the newest k differences ζ: its weights on them
// (±C(k−1, j)), and σ per unit of the median of its length under white noise of σ per component
// (a χ with 3 degrees of freedom, scaled by D^k's noise gain C(2k, k)).
static_assert(3 + 2 + MotionNoiseEstimator::kNoiseOrderAbove <= std::tuple_size_v<decltype(NoiseDifference::weights)>,
              "the highest order the noise estimate reads, at m = 3");
NoiseDifference noise_difference(int k) {
  NoiseDifference d;
  d.order = k;
  for (int j = 0; j < k; ++j) d.weights[static_cast<std::size_t>(j)] = ((k - 1 - j) % 2 == 0 ? 1.0 : -1.0) * binomial(k - 1, j);
  d.sigma_per_median = 1.0 / (kChi3Median * std::sqrt(binomial(2 * k, k)));
  d.var_per_square = 1.0 / (3.0 * binomial(2 * k, k));
  return d;
}

Vec3 newest_difference(std::span<const Vec3> zeta, const NoiseDifference& d) {
  return weighted_vector_sum(0, d.order, [&](int j) { return d.weights[static_cast<std::size_t>(j)]; },
                             zeta.subspan(zeta.size() - static_cast<std::size_t>(d.order)));
}

// How many of the newest kRecentNoiseSamples lengths a history's bits mark, by table (std::popcount
// is a library call on the baseline x86-64 the build targets).
static_assert(MotionNoiseEstimator::kRecentNoiseSamples <= 12, "a table of 2^kRecentNoiseSamples counts");
constexpr auto kNewestMarked = [] {
  std::array<std::uint8_t, 1u << MotionNoiseEstimator::kRecentNoiseSamples> counts{};
  for (std::uint32_t bits = 0; bits < counts.size(); ++bits) counts[bits] = static_cast<std::uint8_t>(std::popcount(bits));
  return counts;
}();

}  // namespace

MotionNoiseEstimator::MotionNoiseEstimator(int capacity, int order)
    : order_(order),
      capacity_(capacity),
      low_(noise_difference(order + 2)),
      fit_(static_cast<std::size_t>(std::max(1, capacity)), 0.0),
      short_fit_(static_cast<std::size_t>(std::max(1, capacity)), 0.0),
      window_fit_(static_cast<std::size_t>(std::max(1, capacity)), 0.0),
      line_weights_(static_cast<std::size_t>(std::max(1, capacity)), 0.0),
      short_line_weights_(static_cast<std::size_t>(std::max(1, capacity)), 0.0) {}

void MotionNoiseEstimator::configure(double rate_hz, const AdaptationSettings& settings, int window) {
  settings_ = settings;
  const int m = order_;
  // The span is motion_span_s at the stream's rate, but never fewer than the m + 1 samples that
  // determine a degree-m polynomial (then the fit is the plain m-th difference). At a low rate
  // a longer minimum would stretch the span in time (m + 3 = 5 samples is 0.5 s at 10 Hz):
  // its centre falls further behind and it averages away motion faster than the span, which
  // the noise estimate then reads as noise (docs/engine.md, "Where it cannot help").
  span_ = std::clamp(static_cast<int>(std::lround(settings.motion_span_s * rate_hz)), m + 1, std::max(m + 1, capacity_));
  span_ = std::min(span_, capacity_);
  fit_noise_gain_ = derivative_fit_weights(span_, m, fit_);
  peak_half_s_ = 0.5 * span_ / rate_hz;
  // The fast part: the same fit over half the span (none where that is under m + 1 samples:
  // 10 Hz with the default span).
  short_span_ = span_ / 2 >= m + 1 ? span_ / 2 : 0;
  if (short_span_ > 0) short_fit_noise_gain_ = derivative_fit_weights(short_span_, m, short_fit_);
  // The least-squares slope of a line through the window (newest_line_slope): its noise gain
  // on θ is 1/Σ(i − c)².
  line_span_ = std::clamp(window, 2, std::max(2, capacity_));
  line_noise_gain_ = 12.0 / (line_span_ * (static_cast<double>(line_span_) * line_span_ - 1.0));
  table_line_weights(line_span_, line_weights_);
  table_line_weights(short_span_, short_line_weights_);
  // The slow part's fit over the window: its m-th derivative has (W/span)^(2m+1) times less noise
  // (32 times at m = 2), so it tells a slow motion from none where the fit above cannot. Not where
  // the window's minimum of samples stretches it past twice the fit's span (under 14 Hz with the
  // defaults): there it averages away motion the fit still sees (TUM's handheld camera at 10 Hz:
  // +2.6% and +3.2% error with it), as a longer fit span did (docs/engine.md).
  const bool window_fit = line_span_ >= m + 1 && line_span_ <= 2.0 * settings.motion_span_s * rate_hz + 1.0;
  window_fit_noise_gain_ = window_fit ? derivative_fit_weights(line_span_, m, window_fit_) : 0.0;
  // The noise estimate's higher order, as high as the window's differences allow (7 at 10 Hz,
  // where the window holds 8 samples), and none if that is not above m + 2.
  const int high = std::min(m + 2 + kNoiseOrderAbove, line_span_ - 1);
  const int high_order = high > m + 2 ? high : 0;
  if (high_order != high_.order) e_.high = {};  // its median was of another order
  high_ = high_order > 0 ? noise_difference(high_order) : NoiseDifference{};
}

void MotionNoiseEstimator::update_median(Estimates::LengthMedian& m, double length, double dt) {
  length = std::max(length, 1e-300);
  if (!m.settled()) {
    // Exact median of the first values: a sound start for the tracker below.
    m.first_lengths[static_cast<std::size_t>(m.count++)] = length;
    std::array<double, 15> sorted = m.first_lengths;
    m.median = upper_median(std::span(sorted).first(static_cast<std::size_t>(m.count)));
  } else {
    // Stochastic approximation of the median in log space: a step up when above, down when
    // below; its time constant is about 1/(2·step) samples. A long run on one side, or a short one
    // far from it, is a noise that changed its level: the step doubles with each length beyond
    // (kNoiseRunSamples, kNoiseFarSamples). The median is kept as itself, each length compared
    // with it, and moved by the factor e^(±step) (RepeatedExp: the step is nearly always the last
    // one's).
    const bool above = length > m.median;
    m.run = above ? std::max(m.run, 0) + 1 : std::min(m.run, 0) - 1;
    const bool far_above = length > kNoiseFarFactor * m.median, far_below = kNoiseFarFactor * length < m.median;
    m.far_run = far_above ? std::max(m.far_run, 0) + 1 : far_below ? std::min(m.far_run, 0) - 1 : 0;
    m.recent_far = (m.recent_far << 1) | (far_above ? 1u : 0u);
    m.recent_square += kRecentNoiseWeight * (length * length - m.recent_square);
    m.steady_square += kSteadyNoiseWeight * (length * length - m.steady_square);
    m.recent_above = (m.recent_above << 1) | (above ? 1u : 0u);
    // Risen where most of the newest lengths stand far above the median, and while most stand
    // above it: the median catching up on a burst (within a second) is not the burst's end.
    const std::uint32_t newest = (1u << kRecentNoiseSamples) - 1u;
    const auto most = [](std::uint32_t bits) { return 2 * kNewestMarked[bits] > kRecentNoiseSamples; };
    m.risen = most(m.recent_far & newest) || (m.risen && most(m.recent_above & newest));
    double step = std::min(0.5, 0.5 * dt / settings_.noise_time_s);
    const int beyond = std::max(std::abs(m.run) - kNoiseRunSamples, std::abs(m.far_run) - kNoiseFarSamples);
    if (beyond > 0) step = std::max(step, std::min(kNoiseRunStepCap, std::ldexp(step, std::min(beyond, 60))));
    m.median *= above ? median_up_(step) : median_down_(-step);
  }
}

double MotionNoiseEstimator::recent_noise_var() const {
  // Not where the newest lengths reach past the motion fit's span (under 30 Hz with the
  // defaults): there a quick turn lasts a few samples and fills most of them.
  if (kRecentNoiseSamples > span_ + 1) return 0.0;
  // Each order's σ² now: its newest lengths' where it reads the noise as risen. Or its median's,
  // where that has caught up with a noise that rose: one order's median may while the other's
  // lags (the tracked σ, the smaller of the two, is then still the old noise's), and the order
  // that caught up no longer reads the noise as risen; its median stands kCaughtUpFactor over
  // the tracked σ² (white noise keeps both orders' medians within a few per cent of each other).
  // Or, where it does neither, its slower mean square's (kSteadyNoiseWeight), where that stands as
  // far over: within a burst an order's risen state drops by chance while its median still lags
  // (the higher order's, at 250 Hz), and the smaller of the two then read no rise. Not after a
  // motion stopped: the slower mean still holds the motion's end (a quick turn's, at 30 Hz).
  auto now = [&](const Estimates::LengthMedian& m, const NoiseDifference& d) {
    if (!m.settled()) return 0.0;
    if (m.risen) return std::max(m.recent_square, m.steady_square) * d.var_per_square;
    const double median_var = std::pow(m.median * d.sigma_per_median, 2);
    if (median_var > kCaughtUpFactor * e_.noise_var) return median_var;
    const double steady_var = m.steady_square * d.var_per_square;
    return e_.stopped_motion == 0.0 && steady_var > kCaughtUpFactor * e_.noise_var ? steady_var : 0.0;
  };
  if (!(e_.low.risen || (high_.order > 0 && e_.high.risen))) return 0.0;
  double v = now(e_.low, low_);
  // Both orders, as the tracked σ: a motion at a third of the rate fills the lower one.
  if (high_.order > 0) v = std::min(v, kNoiseOrderMargin * kNoiseOrderMargin * now(e_.high, high_));
  return v;
}

double MotionNoiseEstimator::newest_half_fit_of_medians(std::span<const Vec3> zeta) const {
  // θ over the newest h + 1 samples, θ_0 = 0 at the oldest (n − h); the half span is samples
  // 1..h. Each is replaced by the median of itself and its two neighbours; the newest, which has
  // no newer neighbour, by the median of itself, the one before and the line through the two
  // medians before (a motion speeding up keeps its speed; an outlier, newest or next to it, is
  // dropped).
  const int h = short_span_;
  const std::size_t base = zeta.size() - static_cast<std::size_t>(h);
  Vec3 before = Vec3::Zero(), here = zeta[base];  // θ_{p−1}, θ_p for p = 1
  Vec3 median_older = Vec3::Zero(), median_before = Vec3::Zero(), sum = Vec3::Zero();
  for (int p = 1; p <= h; ++p) {
    const auto j = static_cast<std::size_t>(p);
    const Vec3 median = p < h ? median_of_three(before, here, here + zeta[base + j])
                              : median_of_three(here, before, 2.0 * median_before - median_older);
    // The fit's weights are on the half span's differences (difference_weights).
    if (p > 1) sum += short_fit_[j - 2] * (median - median_before);
    median_older = median_before;
    median_before = median;
    if (p < h) {
      before = here;
      here += zeta[base + j];
    }
  }
  return sum.squaredNorm() / 3.0;
}

double MotionNoiseEstimator::motion_floor(double fit_noise) const {
  if (!settings_.motion_floor) return 0.0;
  // Where the window's fit is in (on a full window), motion it measures below the fit's noise is
  // taken as it measures it, but never below its own noise.
  if (window_fit_noise_gain_ > 0.0 && e_.window_ready) {
    const double window_noise = e_.noise_var * window_fit_noise_gain_;
    return std::min(fit_noise, std::max(window_noise, e_.window_mean_square - window_noise));
  }
  return fit_noise;
}

bool MotionNoiseEstimator::update(std::span<const Vec3> zeta, double dt, std::span<const Vec3> line_zeta, int measured) {
  const int n1 = static_cast<int>(zeta.size());  // differences available
  if (!(dt > 0.0)) return false;
  const bool was_ready = ready();
  // The rest test's line is taken on a full window only: after a restart its average starts afresh.
  if (n1 < line_span_ - 1) e_.line_ready = e_.window_ready = false;
  bool refreshed = false;
  if (e_.stopped_motion > 0.0 && ++e_.samples_since_stop >= capacity_) e_.stopped_motion = 0.0;
  if (n1 >= low_.order) {
    // D^kθ spans k + 1 samples: one that reaches a stand-in measures its interpolation, not the noise.
    if (measured > low_.order) update_median(e_.low, newest_difference(zeta, low_).norm(), dt);
    double s = e_.low.median * low_.sigma_per_median;
    if (high_.order > 0 && n1 >= high_.order) {
      if (measured > high_.order) update_median(e_.high, newest_difference(zeta, high_).norm(), dt);
      // Once its exact start is complete: a median of a few values is not yet the noise's.
      if (e_.high.settled()) s = std::min(s, kNoiseOrderMargin * e_.high.median * high_.sigma_per_median);
    }
    if (e_.low.count > 0) e_.noise_var = s * s;  // (none yet where only stand-ins' differences came)
  }
  // A rest is judged against the noise the newest samples show where it has risen (kRecentNoiseSamples).
  e_.rest_noise_var = std::max(e_.noise_var, recent_noise_var());
  // The noise each fit lets through, at the noise estimate just updated.
  const double fit_noise = e_.noise_var * fit_noise_gain_;
  const double rest_fit_noise = e_.rest_noise_var * fit_noise_gain_;
  const double short_noise = e_.noise_var * short_fit_noise_gain_;
  // The fit is taken at most kMotionRefreshes times per motion_time_s (every 4 ms by default):
  // the estimate averages over motion_time_s anyway, and fits a few samples apart share nearly
  // all their samples, so at 1 kHz three fits in four would add nothing but their cost (a
  // quarter of the engine's). At rates up to kMotionRefreshes / motion_time_s every sample fits.
  if (span_ > 0 && n1 >= span_ - 1) {
    e_.motion_pending_s += dt;
    // (Less a rounding's worth: four steps of 1 ms may add up to just under 4 ms.)
    if (!e_.motion_ready || e_.motion_pending_s >= (1.0 - 1e-9) * settings_.motion_time_s / kMotionRefreshes) {
      const Vec3 d = weighted_vector_sum(0, span_ - 1, [&](int j) { return fit_[static_cast<std::size_t>(j)]; },
                                         zeta.subspan(static_cast<std::size_t>(n1 - (span_ - 1))));
      double sample = d.squaredNorm() / 3.0;
      const double alpha = e_.motion_ready ? 1.0 - motion_decay_(-e_.motion_pending_s / settings_.motion_time_s) : 1.0;
      // The fast part's fit on the newest half span and on the half before it, the smaller of
      // the two: an outlier sits in one of them, a shake in both.
      auto half_fit = [&](int back) {
        const Vec3 v = weighted_vector_sum(0, short_span_ - 1, [&](int j) { return short_fit_[static_cast<std::size_t>(j)]; },
                                           zeta.subspan(static_cast<std::size_t>(n1 - back - (short_span_ - 1))));
        return v.squaredNorm() / 3.0;
      };
      const double h0 = short_span_ > 0 ? half_fit(0) : 0.0;
      double h1 = short_span_ > 0 ? half_fit(short_span_) : 0.0;
      // After a stop seen on the newest half span (below), the long fit still holds the motion
      // until its span is clear of it: the newest half's fit stands for it, scaled from its noise
      // to the long fit's (so that noise alone reads the same in both, and the onset rule takes a
      // motion starting again as it would), and for the half before it.
      const bool half_stands_in = short_span_ > 0 && e_.stopped_motion > 0.0 && samples_clear_of_stop() < span_;
      if (half_stands_in) {
        sample = h0 * (fit_noise_gain_ / short_fit_noise_gain_);
        h1 = h0;
      }
      e_.mean_square += alpha * (sample - e_.mean_square);
      if (short_span_ > 0) {
        const double fast = std::min(h0, h1);
        e_.short_mean_square += alpha * (fast - e_.short_mean_square);
        // A motion stopping: the averages would come down from a turn at a factor e per
        // motion_time_s once it has left the fits' span, and the end of a turn would be smoothed
        // as lightly as the turn for half a second. Where the motion's average stands clear of the
        // noise (kRestOnsetFactor times the fit's) and the long fit and both half fits are within
        // kMotionStopFactor times their noise, twice running, the motion has stopped, and both
        // averages drop to the noise.
        // Not where the motion is near the noise (its fits are within it half the time): the
        // quality benchmark's 1 kHz set under noise 0.05 lost 0.4% without that condition.
        // A tracker coming to rest is seen sooner on the newest half span alone: its fit within
        // kMotionStopFactor times its noise and the slope of a line through it within its noise
        // (the pose no longer moves, where the fit alone would pass a steady turn), twice running.
        // Only the newest half span is clear of the motion then (kStillSlopeFactor).
        const bool clear_motion = e_.mean_square > kRestOnsetFactor * fit_noise;
        const bool stopped = clear_motion && sample < kMotionStopFactor * fit_noise && std::max(h0, h1) < kMotionStopFactor * short_noise;
        bool half_stopped = false;
        if (!stopped && !half_stands_in && clear_motion && h0 < kMotionStopFactor * short_noise) {
          const LineSlope line = newest_line_slope(zeta, short_span_, short_line_weights_);
          half_stopped = line.slope.squaredNorm() / 3.0 < kStillSlopeFactor * e_.noise_var / line.sxx;
        }
        if ((stopped || half_stopped) && e_.stop_last) {
          // A motion stopped again while one is still in the window: the larger of the two drags,
          // and (while the newest half stands in) the samples clear of it stay as they were.
          e_.stopped_motion = std::max(e_.stopped_motion, e_.mean_square - fit_noise);
          if (!half_stands_in) {
            e_.stop_clear = half_stopped ? short_span_ : span_;
            e_.samples_since_stop = 0;
          }
          e_.mean_square = fit_noise;
          e_.short_mean_square = std::min(e_.short_mean_square, short_noise);
        }
        e_.stop_last = stopped || half_stopped;
      }
      // A motion starting: the average would take motion_time_s to see it, smoothing the start
      // of the motion as hard as what came before. A fit that stands over the onset threshold
      // twice running, and grows, is taken at once: at rest kRestOnsetFactor times its noise
      // (noise alone puts one there once in 40 000 fits), moving an excess over that noise
      // kMotionOnsetFactor times the motion's (or the noise's, if larger). A single outlier's fit
      // is largest as it enters the span and shrinks after; where it grows again (towards the
      // span's centre) it stands at most a quarter as high.
      const double onset = e_.at_rest ? kRestOnsetFactor * rest_fit_noise
                                    : fit_noise + kMotionOnsetFactor * std::max(e_.mean_square - fit_noise, fit_noise);
      const bool over = sample > onset;
      if (over && e_.onset_over && sample > e_.onset_last) {
        // The long fit sees a motion starting at its newest end only dimly (its m-th derivative
        // is taken at the span's centre); the newest half span sees it sooner, and counts where
        // it stands clear of its noise. On the running median, so that outliers (two of them
        // put the long fit over the threshold) are not taken for the motion's size.
        double taken = sample;
        if (short_span_ > 0) {
          const double newest = newest_half_fit_of_medians(zeta);
          if (newest > kOnsetSizeFactor * short_noise) taken = std::max(taken, newest - short_noise + fit_noise);
        }
        e_.mean_square = std::max(e_.mean_square, taken);
      }
      e_.onset_over = over;
      e_.onset_last = sample;
      // The largest fit of the last half to whole span: a vibration's fit passes through zero
      // twice a period, and stands over its noise only now and then.
      e_.peak_s += e_.motion_pending_s;
      if (e_.peak_s >= (1.0 - 1e-9) * peak_half_s_) {  // (less a rounding, as above)
        e_.peak_before = e_.peak;
        e_.peak = 0.0;
        e_.peak_s = 0.0;
      }
      e_.peak = std::max(e_.peak, sample);
      const bool full = n1 >= line_span_ - 1;
      if (settings_.motion_floor && window_fit_noise_gain_ > 0.0 && full) {
        // (Where the span is the window's, as at 1 kHz, it is the same fit as the span's.)
        const Vec3 v = line_span_ == span_ ? d
                                           : weighted_vector_sum(0, line_span_ - 1, [&](int j) { return window_fit_[static_cast<std::size_t>(j)]; },
                                                                 zeta.subspan(static_cast<std::size_t>(n1 - (line_span_ - 1))));
        const double slow = v.squaredNorm() / 3.0;
        e_.window_mean_square = e_.window_ready ? e_.window_mean_square + alpha * (slow - e_.window_mean_square) : slow;
        e_.window_ready = true;
      }
      if (settings_.motion_floor && settings_.rest_threshold > 0.0 && full) {
        const std::span<const Vec3> on = line_zeta.size() == zeta.size() ? line_zeta : zeta;
        // After a motion stopped, the line through the samples clear of it, where they are enough
        // (kRestLineMinSamples) and fewer than the window's: the rest is not put off until the
        // motion has left the window. Its slope's square is scaled to the window line's noise, so
        // that one average and one threshold serve both.
        const int clear = samples_clear_of_stop();
        const bool after_stop = e_.stopped_motion > 0.0 && clear < line_span_ && clear >= std::max(kRestLineMinSamples, span_);
        const LineSlope line = after_stop ? newest_line_slope(on, clear) : newest_line_slope(on, line_span_, line_weights_);
        double slope = line.slope.squaredNorm() / 3.0 * line_noise_gain_ * line.sxx;  // (× 1 on the window's line)
        const double leaves = kRestLeaveFactor * settings_.rest_threshold * e_.rest_noise_var * line_noise_gain_;
        slope = std::min(slope, kRestSlopeCap * leaves);
        // The short line starts its average afresh: the one before held the motion.
        const bool fresh = !e_.line_ready || (after_stop && e_.line_clear == 0);
        e_.line_mean_square = fresh ? slope : e_.line_mean_square + alpha * (slope - e_.line_mean_square);
        e_.line_ready = true;
        e_.line_clear = after_stop ? clear : 0;
      }
      e_.motion_ready = true;
      e_.motion_pending_s = 0.0;
      refreshed = true;
    }
  }
  if (e_.motion_ready) {
    const double threshold = settings_.rest_threshold;
    const double line_noise = e_.rest_noise_var * line_noise_gain_;
    // While the line is not ready again (a window filling after a gap, which the line does not
    // span) a rest stays a rest: FairingWindow ends it where a sample leaves the rest line.
    e_.at_rest = settings_.motion_floor && threshold > 0.0 &&
                 (e_.line_ready ? e_.line_mean_square < (e_.at_rest ? kRestLeaveFactor : 1.0) * threshold * line_noise : e_.at_rest);
    if (e_.at_rest) {
      // The average counts only while a fit stands clear of the noise too: the newest (a motion
      // starting) or one of the last span (a vibration).
      const bool clear = e_.onset_last >= kRestMotionFitFactor * rest_fit_noise ||
                         std::max(e_.peak, e_.peak_before) >= kRestOnsetFactor * rest_fit_noise;
      e_.motion_var = e_.mean_square < threshold * rest_fit_noise || !clear ? 0.0 : e_.mean_square - rest_fit_noise;
    } else {
      e_.motion_var = std::max({motion_floor(fit_noise), e_.mean_square - fit_noise, e_.bias_motion});
    }
    // The fast part counts where it stands clear of the noise its fit lets through.
    const double fast_noise = (e_.at_rest ? e_.rest_noise_var : e_.noise_var) * short_fit_noise_gain_;
    if (short_span_ > 0 && e_.short_mean_square > kFastMotionFactor * fast_noise)
      e_.motion_var = std::max(e_.motion_var, e_.short_mean_square - short_noise);
    if (refreshed) {
      e_.rest_motion_read_before = e_.rest_motion_read;
      e_.rest_motion_read = e_.at_rest && e_.motion_var > 0.0;
    }
  }
  return refreshed || ready() != was_ready;
}

MotionNoiseEstimator::StoppedMotion MotionNoiseEstimator::stopped_motion(int window) const {
  const int clear = samples_clear_of_stop();
  // At rest too: the heaviest level would drag the motion into the still pose.
  if (e_.stopped_motion <= 0.0 || clear >= window - 1) return {};
  return {e_.stopped_motion, clear};
}

void MotionNoiseEstimator::note_correction(double mean_square, double correction_gain, double bias, double dt) {
  if (e_.bias_motion > 0.0 && dt > 0.0) {
    e_.bias_motion *= bias_decay_(-dt / settings_.motion_time_s);
    // Gone where it can no longer count (and before it decays into subnormal numbers).
    if (e_.bias_motion < 1e-6 * e_.noise_var * fit_noise_gain_) e_.bias_motion = 0.0;
  }
  // Twice running, and the smaller of the two: a glitch the outlier guard let through is one
  // large correction (its neighbours' are a fraction of it), a drag after a turn lasts.
  const double noise = e_.noise_var * correction_gain;
  const double implied = bias != 0.0 && mean_square > kBiasFactor * noise ? (mean_square - noise) / (bias * bias) : 0.0;
  if (implied > 0.0 && e_.bias_last > 0.0) e_.bias_motion = std::max(e_.bias_motion, std::min(implied, e_.bias_last));
  e_.bias_last = implied;
}

double best_level(std::span<const EmissionRow> rows, std::span<const double> shared_gain, int count, double noise_var,
                  double motion_var, std::span<const double> tail, double tail_var) {
  if (count <= 1) return 0.0;
  if (tail.empty()) tail_var = 0.0;
  auto tail_of = [&](int l) { return tail_var > 0.0 ? tail[static_cast<std::size_t>(l)] : 0.0; };
  auto cost = [&](int l) {
    const EmissionRow& r = rows[static_cast<std::size_t>(l)];
    const double t = tail_of(l);
    return noise_var * r.noise_gain + motion_var * r.bias * r.bias + tail_var * t * t;
  };
  int best = 0;
  double best_cost = cost(0);
  for (int l = 1; l < count; ++l) {
    const double c = cost(l);
    if (c < best_cost) {
      best_cost = c;
      best = l;
    }
  }
  // Level 0 (no smoothing: the measurement, or with a horizon dead reckoning) stays exact
  // unless a whole level pays. Without a horizon a blend with level 0 gains noise to first order
  // in f and pays bias only to second, so any noise estimate would buy some smoothing, and
  // motion near Nyquist inflates that estimate (docs/engine.md, "Where it cannot help").
  if (best == 0) return 0.0;
  // The blend between levels l and l + 1: its expected error is a quadratic in f with
  // c2 = σ²(G_l − 2G_{l,l+1} + G_{l+1}) + d²(B_{l+1} − B_l)² ≥ 0 (the variance of the rows'
  // difference) and c1 = −2σ²(G_l − G_{l,l+1}) + 2d²B_l(B_{l+1} − B_l); the tail's e²T as the bias.
  double level = best;
  auto refine = [&](int l) {
    if (l < 0 || l + 1 >= count) return;
    const EmissionRow& a = rows[static_cast<std::size_t>(l)];
    const EmissionRow& b = rows[static_cast<std::size_t>(l + 1)];
    const double g = shared_gain[static_cast<std::size_t>(l)];
    const double db = b.bias - a.bias, dt = tail_of(l + 1) - tail_of(l);
    const double c2 = noise_var * (a.noise_gain - 2.0 * g + b.noise_gain) + motion_var * db * db + tail_var * dt * dt;
    const double c1 = -2.0 * noise_var * (a.noise_gain - g) + 2.0 * motion_var * a.bias * db + 2.0 * tail_var * tail_of(l) * dt;
    if (!(c2 > 0.0)) return;
    const double f = std::clamp(-0.5 * c1 / c2, 0.0, 1.0);
    const double c = cost(l) + c1 * f + c2 * f * f;
    if (c < best_cost) {
      best_cost = c;
      level = l + f;
    }
  };
  refine(best - 1);
  refine(best);
  return level;
}

}  // namespace posefair
