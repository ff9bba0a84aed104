#include "posefair/core/smoother_rows.hpp"

#include "posefair/core/combinatorics.hpp"
#include "posefair/core/difference_operators.hpp"

#include <algorithm>
#include <cmath>

namespace posefair {
EmissionRow make_emission_row(int capacity) {
  EmissionRow row;
  row.zeta.assign(static_cast<std::size_t>(std::max(0, capacity - 1)), 0.0);
  row.c.assign(static_cast<std::size_t>(capacity), 0.0);
  return row;
}

EmissionRowBuilder::EmissionRowBuilder(int capacity, int order)
    : capacity_(capacity),
      order_(order),
      system_(capacity, order),
      diag_(static_cast<std::size_t>(capacity)),
      scratch_(static_cast<std::size_t>(capacity) + 1),
      h1_(static_cast<std::size_t>(capacity)),
      h2_(static_cast<std::size_t>(capacity)),
      c1_(static_cast<std::size_t>(capacity)),
      c2_(static_cast<std::size_t>(capacity)) {}

void EmissionRowBuilder::correction_weights(int n, double mu, int k, std::span<double> hk, std::span<double> ck, double kappa,
                                            int emitted) {
  // r = A⁻¹ e_k (A symmetric, so also row k of A⁻¹); e_k = rᵀ(κEc − μ (D^m)ᵀ D^{m−1} ζ), so the
  // weights on ζ are h = −μ (D^{m−1})ᵀ D^m r and those on c are κ r_i (emitted i).
  const int m = order_;
  std::fill(scratch_.begin(), scratch_.begin() + n, Vec3::Zero());
  scratch_[static_cast<std::size_t>(k)] = Vec3::Ones();
  system_.solve(std::span(scratch_).first(static_cast<std::size_t>(n)));
  for (int i = 0; i < n; ++i) ck[static_cast<std::size_t>(i)] = i < emitted ? kappa * scratch_[static_cast<std::size_t>(i)].x() : 0.0;
  std::fill(hk.begin(), hk.begin() + std::max(0, n - 1), 0.0);
  if (n <= m || mu == 0.0) return;
  int len = n;
  const std::span<Vec3> v(scratch_);
  for (int p = 0; p < m; ++p) forward_difference_in_place(v, len--);
  for (int p = 1; p < m; ++p) difference_adjoint_in_place(v, len++);
  for (int j = 0; j < n - 1; ++j) hk[static_cast<std::size_t>(j)] = -mu * scratch_[static_cast<std::size_t>(j)].x();
}

namespace {

// The weight of θ_i in the row's output: θ_k + Σ_j zeta_j (θ_{j+1} − θ_j), so δ_ik + zeta_{i−1} − zeta_i.
double theta_weight(const EmissionRow& row, int n, int k, int i) {
  const auto u = static_cast<std::size_t>(i);
  return (i == k ? 1.0 : 0.0) + (i > 0 ? row.zeta[u - 1] : 0.0) - (i < n - 1 ? row.zeta[u] : 0.0);
}

}  // namespace

double shared_noise_gain(const EmissionRow& a, const EmissionRow& b, int n, int k) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += theta_weight(a, n, k, i) * theta_weight(b, n, k, i);
  return sum;
}

double tail_bias(const EmissionRow& row, int n, const EmissionTarget& target, int clear) {
  const int m = target.order, k = n - 1 - target.lag, s = n - 1 - clear;
  const double mf = factorial(m);
  auto truth = [&](double i) { return i < s ? std::pow(s - i, m) / mf : 0.0; };
  double response = 0.0;
  for (int i = 0; i < s; ++i) response += theta_weight(row, n, k, i) * truth(i);
  return response - truth(k + std::max(0.0, target.horizon));
}

bool EmissionRowBuilder::build(int n, double mu, const EmissionTarget& t, EmissionRow& row) {
  const int m = order_;
  const int k = n - 1 - t.lag;
  const int emitted = k;  // samples before the emitted one have been emitted
  row.mu = mu;
  row.first = 0;
  std::fill(row.zeta.begin(), row.zeta.end(), 0.0);
  std::fill(row.c.begin(), row.c.end(), 0.0);
  row.noise_gain = 1.0;
  row.bias = 0.0;
  row.correction_gain = 0.0;
  if (k < 0) return true;
  for (int i = 0; i < n; ++i) diag_[static_cast<std::size_t>(i)] = 1.0 + (i < emitted ? t.continuity : 0.0);
  if (!assemble_smoothing_system(system_, n, m, mu, std::span(diag_).first(static_cast<std::size_t>(n)))) return false;
  const std::span<double> hz(row.zeta), hc(row.c);
  correction_weights(n, mu, k, hz, hc, t.continuity, emitted);
  const double h = t.horizon;
  if (h > 0.0 && k >= 1) {
    // u = e_k + H ∇x_k (+ H(H+1)/2 ∇²x_k for m = 3), ∇x_k = ζ_{k−1} + e_k − e_{k−1}.
    correction_weights(n, mu, k - 1, h1_, c1_, t.continuity, emitted);
    const bool second = m >= 3 && k >= 2;
    const double c2 = second ? 0.5 * h * (h + 1.0) : 0.0;
    if (second) correction_weights(n, mu, k - 2, h2_, c2_, t.continuity, emitted);
    for (int j = 0; j < n; ++j) {
      const auto i = static_cast<std::size_t>(j);
      const double e1 = j < n - 1 ? h1_[i] : 0.0, e2 = second && j < n - 1 ? h2_[i] : 0.0;
      if (j < n - 1) hz[i] = (1.0 + h + c2) * hz[i] - (h + 2.0 * c2) * e1 + c2 * e2;
      hc[i] = (1.0 + h + c2) * hc[i] - (h + 2.0 * c2) * c1_[i] + (second ? c2 * c2_[i] : 0.0);
    }
    hz[static_cast<std::size_t>(k - 1)] += h + c2;
    if (second) hz[static_cast<std::size_t>(k - 2)] -= c2;
  }
  // The weights on θ (theta_weight) give the row its error model.
  const double target = k + (h > 0.0 ? h : 0.0);
  const double mf = factorial(m);
  double response = 0.0, largest = 0.0;
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    response += theta_weight(row, n, k, i) * std::pow(i - k, m) / mf;
    if (i < n - 1) largest = std::max(largest, std::abs(hz[u]));
    largest = std::max(largest, std::abs(hc[u]));
  }
  row.noise_gain = shared_noise_gain(row, row, n, k);
  row.bias = response - std::pow(target - k, m) / mf;
  row.correction_gain = row.noise_gain - 2.0 * theta_weight(row, n, k, k) + 1.0;
  // Rows decay geometrically into the past: skip what cannot change a double's worth.
  const double negligible = 1e-12 * largest;
  int first = 0;
  while (first < n - 1 && std::abs(hz[static_cast<std::size_t>(first)]) <= negligible && std::abs(hc[static_cast<std::size_t>(first)]) <= negligible)
    ++first;
  row.first = first;
  return true;
}

bool EmissionRowBuilder::solve_window(int n, double mu, const EmissionTarget& t, std::span<const Vec3> zeta, std::span<Vec3> est) {
  const int m = order_;
  const int emitted = n - 1 - t.lag;
  for (int i = 0; i < n; ++i) diag_[static_cast<std::size_t>(i)] = 1.0 + (i < emitted ? t.continuity : 0.0);
  if (!assemble_smoothing_system(system_, n, m, mu, std::span(diag_).first(static_cast<std::size_t>(n)))) return false;
  if (n > m && mu > 0.0) {
    // est −= μ (D^m)ᵀ D^{m−1} ζ.
    std::copy(zeta.begin(), zeta.begin() + (n - 1), scratch_.begin());
    int len = n - 1;
    const std::span<Vec3> v(scratch_);
    for (int p = 1; p < m; ++p) forward_difference_in_place(v, len--);
    for (int p = 0; p < m; ++p) difference_adjoint_in_place(v, len++);
    for (int i = 0; i < n; ++i) est[static_cast<std::size_t>(i)] -= mu * scratch_[static_cast<std::size_t>(i)];
  }
  system_.solve(est.first(static_cast<std::size_t>(n)));
  return true;
}

}  // namespace posefair
