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
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "posefair/core/banded_cholesky.hpp"
#include "posefair/core/fairing_operators.hpp"
#include "posefair/core/sample.hpp"
#include "posefair/core/sample_gate.hpp"

namespace posefair {

enum class WindowSolver { Linear, GaussNewton, DampedSweeps };
enum class BoundPolicy { Sample, Window };

struct WindowConfig {
  int window = 32;                 // W samples
  int lag = 0;                     // L: emit the sample L places behind the newest (0 ≤ L < W)
  int order = 2;                   // m ∈ {2, 3}
  WindowSolver solver = WindowSolver::Linear;
  int iterations = 1;              // Gauss–Newton iterations, or damped sweeps K, per sample
  double smoothing_r = 100.0;      // μ_r (Linear, GaussNewton); see smoothing_for_cutoff()
  double smoothing_t = 100.0;      // μ_t (Linear, GaussNewton)
  double continuity = 0.0;         // κ (Linear, GaussNewton)
  double lambda_r = 0.1;           // DampedSweeps
  double lambda_t = 0.5;           // DampedSweeps
  OperatorVariant variant = OperatorVariant::Corrected;  // DampedSweeps
  double epsilon_r = std::numeric_limits<double>::infinity();  // dist on S³ (rad)
  double epsilon_t = std::numeric_limits<double>::infinity();  // position units
  BoundPolicy bound = BoundPolicy::Sample;  // Window needs an iterative solver
  GateConfig gate;
  double horizon_s = 0.0;          // seconds ahead: emit each pose predicted for sample time + horizon_s (placeholder: the engine does not read it yet)
};

// Largest accepted smoothing weight μ (see validate()).
inline constexpr double kMaxSmoothing = 1e10;

// Throws InvalidEngineSetting (core/engine_setting.hpp, a std::invalid_argument) naming the
// field and its valid range, and the field as setting(). The constructor also
// refuses a continuity κ > 0 that would make the output recursion unstable.
void validate(const WindowConfig& config);

// μ for which the steady-state Whittaker smoother I + μ(D^m)ᵀD^m has gain 1/2 (−6 dB) at
// cutoff_hz for samples at rate_hz: μ = (2 sin(π f_c / f_s))^(−2m).
double smoothing_for_cutoff(double cutoff_hz, double rate_hz, int order);

struct WindowCounters {
  std::uint64_t emitted = 0;
  std::uint64_t clamped = 0;    // emitted poses the ε projection had to move
  std::uint64_t restarts = 0;   // windows restarted after a gap
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
  int size() const { return n_; }
  // Bytes held for this stream (all of it allocated at construction).
  std::size_t memory_bytes() const;

 private:
  void append(const Sample& s);
  void solve();
  void linear_rotation(const BandedCholesky& a);
  void linear_emission_estimate(int k);
  void precompute_linear_rows();
  void check_continuity_stability() const;
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
  int n_ = 0;              // samples in the window
  bool positions_ = false; // this window carries positions (all its samples do)
  bool have_emitted_ = false;
  Quat last_emitted_ = Quat::Identity();

  // Per sample, index 0 = oldest.
  std::vector<Sample> samples_;   // as accepted (time, ids, measured values with their own sign)
  std::vector<Quat> z_;           // measurement, hemisphere-continuous
  std::vector<Quat> x_;           // current estimate (iterative solvers)
  std::vector<Vec3> zeta_;        // ζ_j = log(z_j⁻¹ z_{j+1}) (Linear)
  std::vector<Vec3> est_;         // e_i: estimate x_i = z_i exp(e_i) (Linear)
  std::vector<Vec3> c_;           // log(z_i⁻¹ y_i) of emitted samples (Linear)
  std::vector<char> window_clamped_;  // the window bound moved this sample during a solve
  std::vector<Quat> y_;           // what was emitted (valid for emitted indices)
  std::vector<Vec3> zp_, xp_, yp_;
  // Scratch.
  std::vector<Vec3> e_, u_, w_, rhs_;
  std::vector<Quat> target_;
  std::vector<double> diag_;
  // factors_r_[n], factors_t_[n]: the system for a window holding n samples.
  std::vector<BandedCholesky> factors_r_, factors_t_;
  // Linear: the emitted sample's estimate is a fixed linear function of the window, so its
  // coefficients are precomputed per fill level n (row_zeta_[n]: n-1 weights on ζ, row_c_[n]:
  // n weights on c, row_p_[n]: n weights on z_p + κ y_p). One dot product per sample.
  std::vector<std::vector<double>> row_zeta_, row_c_, row_p_;
};

}  // namespace posefair
