#pragma once
// The linear window solver's emitted pose as fixed weights on the window's data.
//
// For a window of n samples the linearised energy (docs/engine.md) has the exact minimiser
//     e = A⁻¹(κE c − μ (D^m)ᵀ D^{m−1} ζ),   A = I + κE + μ (D^m)ᵀ D^m,
// so the correction e_k of any one sample is a dot product with the measured differences ζ
// (and, with continuity κ, with the emitted corrections c). The engine emits either sample
// k = n−1−L (lag L) or, with a horizon of H samples, the window's fit extrapolated from the
// newest sample to k + H along its last m−1 differences (Newton's backward formula):
//     u = e_k + H ∇x_k                       (m = 2: constant velocity)
//       + H(H+1)/2 ∇²x_k                     (m = 3: constant acceleration)
// with ∇x_k = ζ_{k−1} + e_k − e_{k−1} in the same linearisation, again a dot product.
//
// Each row also knows its own error model, used to choose the smoothing: on data
// θ_i = truth_i + noise (per component variance σ²), the emitted value's noise variance is
// σ²·noise_gain, and on a truth whose m-th difference is a constant d, its error is
// d·bias (zero for polynomials of lower degree, which the smoother keeps exactly). Both are
// computed from the weights themselves, so they hold for any window, lag or horizon.
// Storage is fixed at construction; build() never allocates.
#include <span>
#include <vector>

#include "posefair/core/banded_cholesky.hpp"

namespace posefair {

// What the engine emits for a window of n samples.
struct EmissionTarget {
  int order = 2;            // m
  int lag = 0;              // L (samples)
  double horizon = 0.0;     // H (samples, ≥ 0; needs lag 0)
  double continuity = 0.0;  // κ, on samples already emitted (index < n−1−L)
};

// One set of weights: u = Σ_j zeta[j]·ζ_j + Σ_i c[i]·c_i, nonzero only from index `first` on.
struct EmissionRow {
  double mu = 0.0;
  std::vector<double> zeta;  // n−1 weights
  std::vector<double> c;     // n weights (zero unless κ > 0)
  int first = 0;             // zeta[j] and c[j] are negligible below this index
  double noise_gain = 0.0;   // Σ s_i², s the weights on θ
  double bias = 0.0;         // error per unit m-th difference of the truth
  double correction_gain = 0.0;  // Σ (s_i − δ_ik)²: the noise in the correction (output − measurement)
};

class EmissionRowBuilder {
 public:
  // Storage for windows of up to `capacity` samples, of order m.
  EmissionRowBuilder(int capacity, int order);

  // The row for a window of n samples (order+1 ≤ n ≤ capacity, or fewer: then only the
  // samples present are used) at smoothing μ, into `row` (whose vectors hold capacity).
  // Returns false if the system is not positive definite (never for μ ≥ 0 and κ ≥ 0).
  bool build(int n, double mu, const EmissionTarget& target, EmissionRow& row);

  // Solves the whole window at μ (all n corrections), for a flush: est receives e_i.
  // rhs holds κ·c_i on emitted samples on entry (or zeros); zeta the n−1 differences.
  bool solve_window(int n, double mu, const EmissionTarget& target, std::span<const Vec3> zeta, std::span<Vec3> est);

  int capacity() const { return capacity_; }

 private:
  // r = A⁻¹ e_k into r_, and the weights on ζ of e_k into hk (n−1 entries).
  void correction_weights(int n, double mu, int k, std::span<double> hk, std::span<double> ck, double kappa, int emitted);

  int capacity_, order_;
  BandedCholesky system_;
  std::vector<double> diag_;
  std::vector<Vec3> scratch_;
  std::vector<double> h1_, h2_, c1_, c2_;
};

// Allocates a row able to hold windows of `capacity` samples.
EmissionRow make_emission_row(int capacity);

// Σ_i s_i t_i for the weights s and t that rows a and b (built for the same window of n samples
// emitting sample k) put on θ: on white noise of variance σ² per component, the covariance of
// their outputs is σ² times this (a row with itself: its noise_gain).
double shared_noise_gain(const EmissionRow& a, const EmissionRow& b, int n, int k);

// The row's error per unit m-th difference of a motion that stopped `clear` samples before the
// newest (0 ≤ clear < n − 1): a truth that is a degree-m polynomial up to sample s = n − 1 − clear,
// d·(s − i)^m/m!, and still after it, meeting the still pose there with all its derivatives.
// The row's `bias` is the same for a motion that has not stopped; a heavy row reaches further
// back than `clear` and drags the still pose towards the motion before it.
double tail_bias(const EmissionRow& row, int n, const EmissionTarget& target, int clear);

}  // namespace posefair
