#include "posefair/core/sampled_rotation_energy.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace posefair {

std::vector<Quat> slerp_chain(std::span<const double> key_times, std::span<const Quat> keys,
                              std::span<const double> times) {
  if (key_times.size() < 2 || key_times.size() != keys.size())
    throw std::invalid_argument("slerp_chain: need at least two keys with one time each");
  std::vector<Quat> out;
  out.reserve(times.size());
  for (double t : times) {
    const auto it = std::upper_bound(key_times.begin(), key_times.end(), t);
    const std::size_t i = std::clamp<std::size_t>(static_cast<std::size_t>(it - key_times.begin()), 1, key_times.size() - 1) - 1;
    const double u = std::clamp((t - key_times[i]) / (key_times[i + 1] - key_times[i]), 0.0, 1.0);
    out.push_back(so3::slerp(u, keys[i].normalized(), keys[i + 1].normalized()));
  }
  return out;
}

double sampled_covariant_energy(std::span<const Quat> samples, double dt) {
  if (samples.size() < 3) throw std::invalid_argument("sampled_covariant_energy: need at least three samples");
  std::vector<Quat> q(samples.begin(), samples.end());
  for (Quat& x : q) x.normalize();
  so3::make_continuous(q);
  double energy = 0.0;
  for (std::size_t k = 1; k + 1 < q.size(); ++k) {
    const Eigen::Vector4d c = q[k].coeffs();
    const Eigen::Vector4d a = (q[k + 1].coeffs() - 2.0 * c + q[k - 1].coeffs()) / (dt * dt);
    energy += (a - a.dot(c) * c).squaredNorm() * dt;
  }
  return energy;
}

std::vector<double> uniform_times(double start, double end, double dt) {
  if (!(dt > 0.0) || !(end >= start)) throw std::invalid_argument("uniform_times: need dt > 0 and end >= start");
  const auto n = static_cast<std::size_t>(std::floor((end - start) / dt + 1e-9));
  std::vector<double> t(n + 1);
  for (std::size_t k = 0; k <= n; ++k) t[k] = start + static_cast<double>(k) * dt;
  return t;
}

}  // namespace posefair
