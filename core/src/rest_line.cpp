#include "posefair/core/rest_line.hpp"

#include "posefair/core/combinatorics.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace posefair {
namespace {

// C(k, j) for the moments' orders, k < 5.
constexpr std::array<std::array<double, 5>, 5> kBinomials = [] {
  std::array<std::array<double, 5>, 5> c{};
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j <= k; ++j) c[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)] = binomial(k, j);
  return c;
}();

// Σ w·(a + dt)^k from Σ w·a^j, j ≤ k (the binomial expansion), in place from the top down.
template <class T, std::size_t N>
void age_by(std::array<T, N>& sums, double dt) {
  static_assert(N <= 5);
  for (std::size_t k = N - 1; k >= 1; --k) {
    T shifted = sums[k];
    double power = 1.0;
    for (std::size_t j = k; j-- > 0;) {
      power *= dt;
      shifted += kBinomials[k][j] * power * sums[j];
    }
    sums[k] = shifted;
  }
}

// The Hankel matrix of moments [s_{i+j}] of a fit with `size` coefficients.
Eigen::Matrix3d moments(const std::array<double, 5>& s, int size) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  for (int i = 0; i < size; ++i)
    for (int j = 0; j < size; ++j) m(i, j) = s[static_cast<std::size_t>(i + j)];
  return m;
}

// The inverse of the quadratic fit's moments [s_{i+j}], i, j < 3, by its adjugate, where its
// reciprocal condition number in the 1-norm, 1/(‖M‖₁·‖M⁻¹‖₁), is over 1e-12. Per sample at
// rest: a factorisation and its condition estimate took about an eighth of the engine's time there.
std::optional<Eigen::Matrix3d> inverse_moments(const std::array<double, 5>& s) {
  const double a = s[0], b = s[1], c = s[2], d = s[3], e = s[4];
  Eigen::Matrix3d adj;
  adj(0, 0) = c * e - d * d;
  adj(0, 1) = adj(1, 0) = c * d - b * e;
  adj(0, 2) = adj(2, 0) = b * d - c * c;
  adj(1, 1) = a * e - c * c;
  adj(1, 2) = adj(2, 1) = b * c - a * d;
  adj(2, 2) = a * c - b * b;
  const double det = a * adj(0, 0) + b * adj(0, 1) + c * adj(0, 2);
  if (!(std::abs(det) > 0.0)) return std::nullopt;
  const Eigen::Matrix3d inverse = adj * (1.0 / det);  // (one division, not nine)
  const Eigen::Matrix3d m = moments(s, 3);
  const double rcond = 1.0 / (m.cwiseAbs().colwise().sum().maxCoeff() * inverse.cwiseAbs().colwise().sum().maxCoeff());
  if (!(rcond > 1e-12)) return std::nullopt;
  return inverse;
}

}  // namespace

void RestLine::reset() {
  weights_ = {};
  squares_ = {};
  steps_ = 0;
  values_ = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
}

void RestLine::add(double dt, const Vec3& y, double memory_s, double weight) {
  if (!empty() && dt > 0.0) {
    age_by(weights_, dt);
    age_by(squares_, dt);
    age_by(values_, dt);
    const double decay = decay_(-dt / memory_s);
    for (double& s : weights_) s *= decay;
    for (double& s : squares_) s *= decay * decay;
    for (Vec3& v : values_) v *= decay;
    steps_ = std::min(steps_ + 1, 2);
  }
  // Its noise is 1/weight times the others': w²·(σ²/weight) = weight·σ² in the noise sums.
  weights_[0] += weight;
  squares_[0] += weight;
  values_[0] += weight * y;
}

std::optional<std::array<double, 2>> RestLine::line_weights(double age) const {
  // The 2×2 normal equations of the line, solved in closed form: [w0 w1; w1 w2]·p = [1, age].
  if (steps_ < 2) return std::nullopt;  // fewer than three distinct times (value_at's quadratic has none)
  const double w0 = weights_[0], w1 = weights_[1], w2 = weights_[2];
  const double det = w0 * w2 - w1 * w1;
  if (!(det > 1e-12 * w0 * w2)) return std::nullopt;
  const double inverse = 1.0 / det;
  return std::array<double, 2>{(w2 - w1 * age) * inverse, (w0 * age - w1) * inverse};
}

std::optional<Vec3> RestLine::line_at(double age) const {
  const std::optional<std::array<double, 2>> p = line_weights(age);
  if (!p) return std::nullopt;
  return (*p)[0] * values_[0] + (*p)[1] * values_[1];
}

std::optional<RestLine::Value> RestLine::value_at(double age, double noise_var, double factor) const {
  // Each fit's value at `age` is Σ w_i·(pᵀ[1, a_i, a_i²])·y_i with p = M⁻¹[1, age, age²] and M
  // the fit's moments; the difference of the two fits has weights w_i·dᵀ[1, a_i, a_i²] with
  // d = p_quadratic − p_line, and its noise gain is dᵀ[Σ w²a^(i+j)]d.
  if (steps_ < 2) return std::nullopt;  // fewer than three distinct times: no quadratic
  const std::optional<Eigen::Matrix3d> quadratic = inverse_moments(weights_);
  if (!quadratic) return std::nullopt;
  const std::optional<std::array<double, 2>> line = line_weights(age);
  if (!line) return std::nullopt;
  const Eigen::Vector3d p_line((*line)[0], (*line)[1], 0.0);
  const Eigen::Vector3d p_quadratic = *quadratic * Eigen::Vector3d(1.0, age, age * age);
  const Eigen::Vector3d d = p_quadratic - p_line;
  const double gain = d.dot(moments(squares_, 3) * d);
  const Vec3 difference = d(0) * values_[0] + d(1) * values_[1] + d(2) * values_[2];
  const Vec3 line_value = p_line(0) * values_[0] + p_line(1) * values_[1];
  // Moved toward the level by w = −C/(V + b²), the weight with the least expected square error:
  // C the covariance of the line's noise with the level-minus-line difference's, V that
  // difference's noise, b² its bias, taken as kLevelBiasFactor times its mean square.
  // Both are lines in the samples' ages: weights (p0, p1) and (e0, e1) on Σw·y and Σw·a·y.
  const double p0 = p_line(0), p1 = p_line(1), e0 = 1.0 / weights_[0] - p0, e1 = -p1;
  const double s0 = squares_[0], s1 = squares_[1], s2 = squares_[2];
  const Vec3 level_minus_line = e0 * values_[0] + e1 * values_[1];
  const double noise = (e0 * e0 * s0 + 2.0 * e0 * e1 * s1 + e1 * e1 * s2) * noise_var;
  const double covariance = (p0 * e0 * s0 + (p0 * e1 + p1 * e0) * s1 + p1 * e1 * s2) * noise_var;
  const double denominator = noise + kLevelBiasFactor * level_minus_line.squaredNorm() / 3.0;
  const double w = denominator > 0.0 ? std::clamp(-covariance / denominator, 0.0, 1.0) : 0.0;
  return Value{line_value + w * level_minus_line, difference.squaredNorm() / 3.0 < factor * noise_var * gain};
}

}  // namespace posefair
