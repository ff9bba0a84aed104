#pragma once
// The real-time engine for one stream: a sliding window of the newest W samples, faired again
// for every new sample (warm-started from the previous window), emitting the pose at lag L.
//
// Every solver minimises over the window (or, for the paper's sweeps, descends)
//       Σ_i ‖log(z_i⁻¹ x_i)‖² + μ_r Σ_j ‖W^m x_j‖² + κ Σ_{i emitted} ‖log(y_i⁻¹ x_i)‖²
// i.e. Lee & Shin's energy E_m^r plus a data term (and, with κ > 0, a pull toward the poses
// already emitted, so the output continues smoothly from what consumers have seen).
//   Linear (default): the energy linearised once in the chart of each measurement,
//     x_i = z_i exp(e_i), W¹x_j ≈ ζ_j + e_{j+1} − e_j with ζ_j = log(z_j⁻¹ z_{j+1}); its exact
//     minimiser is one banded solve (I + κE + μ (D^m)ᵀD^m) e = κE c − μ (D^m)ᵀ D^{m−1} ζ per
//     sample, with the Cholesky factor computed at construction. Neglects terms of order
//     ‖ζ‖·‖e‖ (motion per sample times correction).
//   GaussNewton: the same normal equations relinearised at the current estimate each
//     iteration (warm-started from the previous window), with the Jacobians of log taken as
//     the identity: its fixed point differs from the exact minimiser by second-order terms.
//   DampedSweeps: K of the paper's damped operator sweeps (eqs. 16–18) per sample: the reference.
// Positions are linear and solved exactly by Linear and GaussNewton.
// docs/engine.md derives the solvers and compares them.
// The bound ε is a hard promise on every emitted pose: dist(output, measurement) ≤ ε_r (dist on
// S³, half the rotation angle) and ‖p − p_measured‖ ≤ ε_t, enforced by projecting onto the
// ε-ball either at emission only (BoundPolicy::Sample) or for every window sample after every
// iteration (BoundPolicy::Window), and checked in the distance the promise is stated in.
// Memory is fixed at construction; push() and flush() never allocate.
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "posefair/core/banded_cholesky.hpp"
#include "posefair/core/fairing_operators.hpp"
#include "posefair/core/gyro_aiding.hpp"
#include "posefair/core/outlier_guard.hpp"
#include "posefair/core/prediction_check.hpp"
#include "posefair/core/repeated_measurements.hpp"
#include "posefair/core/slerped_measurements.hpp"
#include "posefair/core/rest_line.hpp"
#include "posefair/core/sample.hpp"
#include "posefair/core/sample_gate.hpp"
#include "posefair/core/sliding_array.hpp"
#include "posefair/core/smoother_rows.hpp"
#include "posefair/core/smoothing_adaptation.hpp"
#include "posefair/core/stream_rate.hpp"

namespace posefair {

enum class WindowSolver { Linear, GaussNewton, DampedSweeps };
enum class BoundPolicy { Sample, Window };

// The defaults are the engine's, the CLI's and the daemon's alike (docs/engine.md): a window of
// half a second at the stream's rate, order 2, no lag, and smoothing adapted to the stream's
// own noise and motion. A setting given in samples or as μ is used exactly as given.
struct WindowConfig {
  int window = 0;                  // W samples; 0: window_s at the stream's rate
  double window_s = 0.5;           // the window as a time span (when window is 0)
  int max_window = 128;            // the largest W that window_s may give (cost and memory grow with W)
  int lag = 0;                     // L: emit the sample L places behind the newest (0 ≤ L < W)
  double horizon_s = 0.0;          // > 0: emit the pose predicted this far past the newest sample
  int order = 2;                   // m ∈ {2, 3}
  WindowSolver solver = WindowSolver::Linear;
  int iterations = 1;              // Gauss–Newton iterations, or damped sweeps K, per sample
  std::optional<double> smoothing_r;  // μ_r; unset: from cutoff_hz, else adapted (Linear only)
  std::optional<double> smoothing_t;  // μ_t, the same for positions
  std::optional<double> cutoff_hz;    // μ from this cutoff (Hz) at the stream's rate; see smoothing_for_cutoff()
  double rate_hz = 0.0;            // the stream's rate; 0: measured from its first intervals
  AdaptationSettings adaptation;   // when smoothing is adapted
  double continuity = 0.0;         // κ (Linear, GaussNewton)
  double lambda_r = 0.1;           // DampedSweeps
  double lambda_t = 0.5;           // DampedSweeps
  OperatorVariant variant = OperatorVariant::Corrected;  // DampedSweeps
  double epsilon_r = std::numeric_limits<double>::infinity();  // dist on S³ (rad)
  double epsilon_t = std::numeric_limits<double>::infinity();  // position units
  BoundPolicy bound = BoundPolicy::Sample;  // Window needs an iterative solver
  GateConfig gate;
  // A lone sample further from the prediction of the ones before it than this many times the
  // median of that distance, right after an ordinary one, is held at the prediction
  // (outlier_guard.hpp); 0: off. At lag 0 its pose is emitted as measured (an outlier and a
  // sudden motion's first sample look alike until the next sample), and the prediction takes
  // its place for the poses after it. Unset: kDefaultOutlierThreshold, but off for an iterative
  // solver at lag 0 (which would emit the held sample at the prediction).
  std::optional<double> outlier_threshold;
  // Samples with a gyroscope reading (kHasGyro) put the smoothness on the orientation's angular
  // velocity minus the gyro's (gyro_aiding.hpp); linear solver, no horizon. Up to
  // kMaxBridgedGyroReadings missing readings in a row are bridged; more restart the window.
  GyroAidingSettings gyro;
};

// The outlier guard's threshold where none is given.
inline constexpr double kDefaultOutlierThreshold = 8.0;
// The threshold in use: given, or the default (kDefaultOutlierThreshold; 0 where a held sample
// would be emitted at the prediction at lag 0: an iterative solver).
double outlier_threshold(const WindowConfig& config);
// Whether a held sample's pose is emitted as measured (held only for the poses after it): at lag 0
// with the linear solver. Otherwise it is emitted at the prediction unless released first.
bool emits_held_as_measured(const WindowConfig& config);

// Largest accepted smoothing weight μ (see validate()).
inline constexpr double kMaxSmoothing = 1e10;
// The shortest window window_s may give.
inline constexpr int kMinWindowSamples = 8;
// A step this close to a whole number j ≥ 2 of the stream's intervals (in intervals), and no gap,
// lost j − 1 samples (a radio tracker's lost packets): the window stands in for them on the
// line between their neighbours, at most kMaxLostInStep per step.
inline constexpr double kLostStepTolerance = 0.25;
inline constexpr int kMaxLostInStep = 8;
// Nothing is stood in for this long (seconds) after a step off the grid of whole intervals: the
// stamps jitter, and a long step may be a late sample (FairingWindow::note_step_grid).
inline constexpr double kOffGridMemory = 2.0;
// Candidate smoothing levels of the adaptation (a third of an octave of cutoff apart).
inline constexpr int kMaxSmoothingLevels = 28;

// Throws InvalidEngineSetting (core/engine_setting.hpp, a std::invalid_argument) naming the
// field and its valid range, and the field as setting(). The constructor also
// refuses a continuity κ > 0 that would make the output recursion unstable.
void validate(const WindowConfig& config);

// μ for which the steady-state Whittaker smoother I + μ(D^m)ᵀD^m has gain 1/2 (−6 dB) at
// cutoff_hz for samples at rate_hz: μ = (2 sin(π f_c / f_s))^(−2m).
double smoothing_for_cutoff(double cutoff_hz, double rate_hz, int order);
// Its inverse: the cutoff (Hz) of μ at rate_hz.
double cutoff_for_smoothing(double mu, double rate_hz, int order);

struct WindowCounters {
  std::uint64_t emitted = 0;
  std::uint64_t clamped = 0;    // emitted poses the ε projection had to move
  std::uint64_t restarts = 0;   // windows restarted after a gap, a change of rate, or for samples with/without positions or gyro
  std::uint64_t rate_changes = 0;  // of those, for a change of the measured rate (the window restarted at the new one)
  std::uint64_t gyro_bridged = 0;  // readings missing from a gyro-aided window, bridged without a restart
  std::uint64_t held = 0;          // outliers held at the prediction (rotation, position or both)
  std::uint64_t released = 0;      // of those, taken back: the next sample showed a motion starting
  // Samples that repeated the measurement before, in a stream read faster than its source
  // updates (repeated_measurements.hpp): carried forward from the poses before, not faired.
  std::uint64_t repeated = 0;
  // A stream slerped from a slower source (slerped_measurements.hpp): its samples, interpolated
  // between the poses faired for the measurements it holds, and those measurements (faired, not
  // delivered).
  std::uint64_t interpolated = 0;
  std::uint64_t slerp_measurements = 0;
  // Samples lost within a step (one of two to four intervals with the default gate; a longer
  // one is a gap): stood in for on the line between their neighbours, faired across, not emitted.
  std::uint64_t lost = 0;
};

// What the engine is doing now: the rate and window it settled on and, per channel, what the
// adaptation measured and chose (or the fixed smoothing). For counters and STATUS=.
struct ChannelAdaptation {
  bool adaptive = false;
  double noise = 0.0;      // RMS measurement noise per sample (rad of rotation angle, or position units)
  double motion = 0.0;     // RMS m-th time derivative of the motion (rad/s^m, or units/s^m)
  double smoothing = 0.0;  // μ in use
  double cutoff_hz = 0.0;  // the cutoff μ corresponds to at the rate (0 while the rate is unknown)
  bool at_rest = false;    // adapted: the stream is still, and smoothed as hard as the window allows (smoothing_adaptation.hpp)
  bool rest_averaged = false;  // at rest and averaged over seconds, not the window (rest_line.hpp)
  // adapted at lag 0: the factor on the noise variance that the check by the next measurement
  // took (prediction_check.hpp); 1 where the noise estimate stands
  double noise_scale = 1.0;
  // adapted: the noise a rest is judged against (same unit as noise): the newest samples' where
  // it has risen over the estimate lately (a burst of noise, smoothing_adaptation.hpp
  // kRecentNoiseSamples), else the estimate's
  double rest_noise = 0.0;
};
struct EngineState {
  double rate_hz = 0.0;    // given or measured; 0 until known (the source's while repeating)
  int window = 0;          // W in use
  // The stream repeats each measurement (read faster than its source updates): the window
  // holds the measurements alone, at the source's rate, and each repeat is carried forward.
  bool repeating = false;
  // The stream is slerped from a slower source: the window holds the measurements it holds, at
  // the source's rate, and each sample is interpolated between the poses faired for them.
  bool slerped = false;
  ChannelAdaptation rotation, position;
  GyroAidingState gyro;
};

class FairingWindow {
 public:
  explicit FairingWindow(const WindowConfig& config);

  // Most poses one push() or flush() can emit (a gap flushes up to L pending ones first).
  int max_outputs_per_push() const { return config_.lag + 1; }

  // Gates, windows and fairs one sample; writes the poses it emits to out (which must hold
  // max_outputs_per_push()) and returns how many. Rejected and dropped samples emit nothing.
  int push(const Sample& sample, std::span<FairedPose> out);

  // Emits every sample still held back by the lag (end of stream), then starts afresh.
  int flush(std::span<FairedPose> out);

  const WindowCounters& counters() const { return counters_; }
  const GateCounters& gate_counters() const { return gate_.counters(); }
  const WindowConfig& config() const { return config_; }
  EngineState state() const;
  int size() const { return n_; }
  // Bytes held for this stream (all of it allocated at construction).
  std::size_t memory_bytes() const;

 private:
  // One half of the linear solver's state: rotation (ζ = log(z_j⁻¹ z_{j+1})) or position
  // (ζ = p_{j+1} − p_j), which share the emission rows but choose their smoothing apart.
  struct Channel {
    Channel(int capacity, int order);
    bool adaptive = true;
    double mu = 0.0;            // fixed μ, or the adapted one
    double level = 0.0;         // adapted: real index into levels_
    EmissionRow fixed;          // fixed μ: the full window's row
    // Adapted, between two levels: their rows' weights on ζ blended for the level in use, kept
    // while it stays (at 1 kHz the level is chosen every fourth sample); level −1: none yet.
    struct Blend {
      std::vector<double> zeta;
      int first = 0;
      double level = -1.0;
    } blend;
    MotionNoiseEstimator estimator;
    // At rest (adapted): the line through the samples since the rest began (in
    // rest_coordinate, from the rest's first pose R or position p_0), the time of the last
    // sample it took, whether the channel is at rest now, the line's weight in the output, and
    // whether the line is straight.
    struct Rest {
      RestLine line;
      Quat reference = Quat::Identity();  // rotations: R
      Vec3 origin = Vec3::Zero();         // positions: p_0
      double time = 0.0;
      bool resting = false;
      double weight = 0.0;
      bool averaged = false;
      Vec3 departure = Vec3::Zero();  // how far the newest sample left the line (zero: it did not)
      // After a motion left rest (emitted as measured): the samples for which the next ones still
      // go out as measured while the level's correction stands over the noise (linear_emission_estimate).
      int leaving = 0;
    } rest;
    // What the stream's first samples off the rest line turned out to be (departs_from_rest), each
    // judgement's weight decayed by kDepartureMemory per later one: a motion starting (the next
    // sample off on the same side, or rest ended) or alone (a noise spike, a glitch). The prior:
    // one spike. Kept over held samples and restarts: it is the stream's.
    struct Departures {
      double first_off_time = std::numeric_limits<double>::infinity();  // the newest first off, to judge
      double starts = 0.0, spikes = 1.0;
      double first_off_square = 0.0;  // ‖e‖² of the newest first off, from the line's prediction
      double start_square = 0.0;      // the furthest of those that began motions (decayed alike)
    } departures;
    // The noise estimate checked by the next measurement (prediction_check.hpp): its candidates'
    // levels, chosen with the noise scaled by PredictionCheck::scale(j).
    PredictionCheck check;
    std::array<double, PredictionCheck::kCandidates> candidate_level{};
    // A window filling again after a gap smooths as the adaptation last chose (at rest, as hard as
    // it can), though its fits cannot see a motion until they span enough samples: set where a
    // sample stood off the fill's estimate by more than the noise could put it (fill_moves), and
    // the window then fills unsmoothed until the motion estimate is refreshed.
    bool filling_moved = false;
  };
  // What a channel's adaptation had learnt before a held sample went in: put back when the next
  // sample releases it, and the released sample learnt from as measured, so that a released
  // sample leaves the stream as if it had never been held. Fixed size: no allocation.
  struct Learnt {
    MotionNoiseEstimator::Estimates estimates;
    double mu = 0.0, level = 0.0;
    Channel::Rest rest;
    PredictionCheck::State check;
    std::array<double, PredictionCheck::kCandidates> candidate_level{};
    bool filling_moved = false;
  };
  static Learnt learnt(const Channel& ch) {
    return {ch.estimator.estimates(), ch.mu, ch.level, ch.rest, ch.check.state(), ch.candidate_level, ch.filling_moved};
  }
  static void restore(Channel& ch, const Learnt& l);

  // held_'s bits: which channel of a sample holds the prediction.
  static constexpr char kHeldRotation = 1, kHeldPosition = 2;
  bool hold_outliers(const Sample& s, double step, Quat& z, Vec3& p, char& held);
  void put_held(const Quat& z, const Vec3& p, char held, double dt);
  void append(const Sample& s);
  bool stands_in() const;
  int lost_in_step(double step) const;
  void note_step_grid(double step);
  int stand_in(const Sample& s, double f, double dt, std::span<FairedPose> out);
  bool gyro_aided(const Sample& s) const;
  // What the rotation rows apply to: the measured increments ζ, or with a gyro their residual.
  const SlidingArray<Vec3>& rotation_increments() const { return aided_ ? residual_ : zeta_; }
  void note_interval(double dt);
  double rate_change(double step);
  double typical_interval() const;
  bool needs_rate() const;
  void prepare(double rate_hz);
  void slide(int count);
  void adapt(Channel& ch, std::span<const Vec3> zeta, double dt);
  bool checks_prediction(const Channel& ch) const;
  void compare_predictions(Channel& ch, std::span<const Vec3> zeta);
  void predict_next(Channel& ch, std::span<const Vec3> zeta);
  std::span<const Vec3> rest_increments(int count);
  enum class Departure { None, Off, Moving };
  Departure departs_from_rest(Channel& ch);
  Vec3 rest_coordinate(const Channel& ch, int j) const;
  std::optional<Vec3> from_rest_line(const Channel& ch) const;
  char newest_held_ = 0;  // the channels whose newest sample the guard held (kHeld*; at lag 0 emitted as measured all the same)
  bool emitting_held_ = false;  // that sample's estimate is being made as measured, to emit it (lag 0)
  void note_correction(Channel& ch, int k, const Vec3& u, double dt);
  struct LevelRows {
    const EmissionRow& a;
    const EmissionRow& b;
    double f;
    // One of the rows' error figures (noise_gain, bias, correction_gain) for the blend.
    double blended(double EmissionRow::*figure) const { return (1.0 - f) * a.*figure + f * b.*figure; }
  };
  LevelRows level_rows(const Channel& ch) const;
  double correction_gain(const Channel& ch) const;  // of the level in use
  Vec3 linear_correction(Channel& ch, std::span<const Vec3> zeta, std::span<const Vec3> c);
  bool fill_moves(const Channel& ch, std::span<const Vec3> zeta);
  void follow_rest(Channel& ch, bool departs);
  // The rest line's part in sample k's correction: its weight and its pose (weight 0: none).
  struct RestPart {
    double weight = 0.0;
    Vec3 pose = Vec3::Zero();
    Vec3 over(const Vec3& window) const { return weight > 0.0 ? (window + weight * (pose - window)).eval() : window; }
  };
  static constexpr double kWholeRest = 1e-3;  // the line's weight this near whole is whole (rest_part)
  RestPart rest_part(Channel& ch, int k, double dt);
  void linear_emission_estimate(int k, double dt);
  void predict_from_last_step(int k, double step);
  bool carries_repeats() const;
  int start_afresh(std::span<FairedPose> out);
  int fair(const Sample& sample, std::span<FairedPose> out);
  int interpolate_slerped(const Sample& sample, const SlerpKnot* next, std::span<FairedPose> out);
  FairedPose carry_forward(const Sample& s);
  double carried_share(const Channel& ch, const Vec3& step) const;
  void note_window_pose(FairedPose& pose, double time);
  void check_continuity_stability() const;
  void solve();
  void linear_window();
  void gauss_newton_rotation(const BandedCholesky& a);
  void smoothness_gradient(std::span<const Vec3> w1);
  void solve_positions(const BandedCholesky& a);
  void sweeps();
  void bound_window();
  FairedPose emit(int index);
  int emit_pending(std::span<FairedPose> out);
  int first_unemitted() const;

  WindowConfig config_;
  SampleGate gate_;
  WindowCounters counters_;
  int capacity_ = 0;       // storage, in samples
  int w_ = 0;              // W in use (capacity_ until the rate is known)
  int n_ = 0;              // samples in the window
  bool positions_ = false; // this window carries positions (all its samples do)
  bool aided_ = false;     // this window is gyro-aided (its samples carry a gyro, but for bridged gaps)
  int missing_gyro_run_ = 0;  // readings missing in a row at the newest end of an aided window
  bool have_emitted_ = false;
  Quat last_emitted_ = Quat::Identity();
  double last_time_ = 0.0;
  bool have_time_ = false;
  // The last accepted measurement, kept across a restart: a prediction the window cannot make
  // yet extrapolates the step from it (predict_from_last_step).
  Quat last_z_ = Quat::Identity();
  Vec3 last_p_ = Vec3::Zero();
  bool last_has_position_ = false;
  // The newest increment the outlier guard took, log(from⁻¹to), with its two ends: append() takes
  // it where its sample's ends are the same, instead of the same logarithm again.
  struct KnownIncrement {
    Quat from = Quat::Identity(), to = Quat::Identity();
    Vec3 log = Vec3::Zero();
  };
  KnownIncrement known_increment_;
  Vec3 increment_log(const Quat& from, const Quat& to) const;
  // A stream that repeats its measurements: what tells it, and the last two poses the window
  // emitted (lag 0) with their samples' times, which a repeat carries forward.
  RepeatedMeasurements repeats_;
  bool repeating_ = false;  // the window holds the measurements alone, and carries the repeats
  // A stream slerped from a slower source: what tells it and reconstructs its measurements.
  SlerpedMeasurements slerps_;
  bool slerped_ = false;  // the window holds the measurements alone, and interpolates the samples
  double slerp_time_ = -std::numeric_limits<double>::infinity();  // the newest sample interpolated
  struct WindowPoses {
    std::array<Quat, 2> orientation{Quat::Identity(), Quat::Identity()};
    std::array<Vec3, 2> position{Vec3::Zero(), Vec3::Zero()};
    std::array<double, 2> time{};
    int count = 0;  // since the window (re)started, up to 2
  } window_poses_;
  double carried_time_ = -1.0;  // the newest carried repeat's time since the window's last pose (< 0: none)
  double afresh_from_ = -1.0;   // the last pose's time, when the window started afresh since (< 0: it did not)

  // The rate: given, or measured from the first intervals (stream_rate.hpp) and checked on
  // in blocks of kMaxRateIntervals steps (rate_change).
  double rate_ = 0.0;
  bool prepared_ = false;  // W, the rows and the estimators are set for rate_
  bool rate_measured_ = false;
  StreamRateEstimate rate_estimate_;
  StreamRateEstimate rate_check_{kMaxRateIntervals};
  double rate_candidate_ = 0.0;  // a block's rate that differed from rate_, awaiting the next

  // Linear solver.
  EmissionTarget target_spec_;
  EmissionRowBuilder builder_;
  std::vector<EmissionRow> next_rows_;  // the levels' predictions of the next sample (checks_prediction)
  std::vector<EmissionRow> levels_;  // candidate rows for the adaptation, least smoothing first
  std::array<double, kMaxSmoothingLevels> level_shared_gain_{};  // [l]: shared_noise_gain of levels l, l + 1
  int level_count_ = 0;
  // [c·kMaxSmoothingLevels + l]: level l's |tail_bias| for a motion that stopped c or more
  // samples before the newest, the largest (c < W − 1).
  std::vector<double> level_tail_bias_;
  EmissionRow fill_row_;             // scratch: the row of a window still filling
  EmissionRow fill_newest_row_;      // scratch: its estimate of the newest sample (fill_moves)
  Channel rot_, pos_;
  OutlierGuard rot_guard_, pos_guard_;
  // Before the newest sample was held: both channels' adaptation, and the step it came after
  // (valid while before_hold_dt_ >= 0).
  Learnt rot_before_hold_, pos_before_hold_;
  double before_hold_dt_ = -1.0;
  GyroAiding gyro_;
  // The rotation's adaptation while gyro-aided: the residual is slow, so its motion is fitted
  // over the whole window (a shorter fit passes so much noise that it would pass for motion).
  MotionNoiseEstimator aided_estimator_;

  // Per sample, index 0 = oldest.
  // As accepted (ids, measured values with their own sign), but timed by when they were taken:
  // their stamps, moved by the sum of what the gate's sampled steps differ from the stamped ones
  // (sampled_offset_), so a clump's samples are an interval apart for the gyro aiding too.
  SlidingArray<Sample> samples_;
  SlidingArray<double> stamp_;         // each sample's own time, which its pose is stamped with
  SlidingArray<double> sampled_step_;  // the gate's sampled_step() of each
  double sampled_offset_ = 0.0;
  SlidingArray<Quat> z_;           // measurement, hemisphere-continuous
  SlidingArray<Quat> x_;           // current estimate (iterative solvers)
  SlidingArray<Vec3> zeta_;        // ζ_j = log(z_j⁻¹ z_{j+1}) (Linear)
  SlidingArray<Vec3> residual_;    // ζ_j − g_j, the gyro-aided increments (Linear, aided)
  // At rest: log(R⁻¹z_{j+1}) − log(R⁻¹z_j) on the rest line's chart (R: its reference), for the
  // rest test's line; valid while rest_chart_ready_, for rest_chart_reference_.
  SlidingArray<Vec3> rest_zeta_;
  Quat rest_chart_reference_ = Quat::Identity();
  bool rest_chart_ready_ = false;
  // The newest rotations' rest coordinates, log(R⁻¹z): at rest the newest sample's is wanted by the
  // departure test, the rest test's increments and the line, and the one before it by the
  // increments again (one log per sample instead of four). Keyed by R and z themselves.
  struct RestChartMemo {
    Eigen::Vector4d reference = Eigen::Vector4d::Zero(), z = Eigen::Vector4d::Zero();  // (no unit quaternion)
    Vec3 coordinate = Vec3::Zero();
  };
  mutable std::array<RestChartMemo, 2> rest_chart_memo_{};
  mutable std::size_t rest_chart_memo_next_ = 0;
  SlidingArray<Vec3> est_;         // e_i: estimate x_i = z_i exp(e_i) (Linear)
  SlidingArray<Vec3> c_;           // log(z_i⁻¹ y_i) of emitted samples (Linear)
  SlidingArray<Vec3> dzp_;         // p_{j+1} − p_j (Linear)
  SlidingArray<Vec3> cp_;          // y_p,i − z_p,i of emitted samples (Linear)
  SlidingArray<char> window_clamped_;  // the window bound moved this sample during a solve
  // A sample lost within a step, stood in for on the line between its neighbours (lost_in_step):
  // faired as the window's others, never emitted, and its differences are no measure of noise.
  SlidingArray<char> stand_in_;
  static constexpr int kNoStandIn = 1 << 20;
  int since_stand_in_ = kNoStandIn;  // samples appended since the newest stand-in (at most kNoStandIn: none lately)
  double off_grid_time_ = -std::numeric_limits<double>::infinity();  // the newest step off the grid of intervals
  SlidingArray<char> held_;        // an outlier held (kHeldRotation, kHeldPosition): z_/zp_ hold the prediction, samples_ the measurement
  SlidingArray<Quat> y_;           // what was emitted (valid for emitted indices)
  SlidingArray<Vec3> zp_, xp_, yp_;
  // Scratch.
  std::vector<Vec3> e_, u_, w_scratch_, rhs_;
  std::vector<Quat> target_;
  std::vector<double> diag_;
  // Iterative solvers: factors_r_[n], factors_t_[n], the system for a window holding n samples.
  std::vector<BandedCholesky> factors_r_, factors_t_;
};

}  // namespace posefair
