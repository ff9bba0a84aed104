#include "posefair/core/difference_operators.hpp"

#include <stdexcept>
#include <string>

namespace posefair {
namespace {

void require_length(std::size_t n, int m) {
  if (m < 1) throw std::invalid_argument("difference order must be at least 1, got " + std::to_string(m));
  if (n < static_cast<std::size_t>(m) + 1)
    throw std::invalid_argument("an order-" + std::to_string(m) + " difference needs at least " +
                                std::to_string(m + 1) + " samples, got " + std::to_string(n));
}

// Repeated forward differencing in place: after k passes the first n-k entries hold D^k.
void difference_in_place(std::vector<Vec3>& d, int passes) {
  for (int k = 0; k < passes; ++k) {
    for (std::size_t i = 0; i + 1 < d.size(); ++i) d[i] = d[i + 1] - d[i];
    d.pop_back();
  }
}

double sum_squared_norms(const std::vector<Vec3>& d) {
  double e = 0.0;
  for (const Vec3& v : d) e += v.squaredNorm();
  return e;
}

}  // namespace

std::vector<Vec3> position_differences(std::span<const Vec3> p, int m) {
  require_length(p.size(), m);
  std::vector<Vec3> d(p.begin(), p.end());
  difference_in_place(d, m);
  return d;
}

std::vector<Vec3> orientation_differences(std::span<const Quat> q, int m) {
  require_length(q.size(), m);
  std::vector<Vec3> d(q.size() - 1);
  for (std::size_t i = 0; i + 1 < q.size(); ++i) d[i] = so3::log(q[i].conjugate() * q[i + 1]);
  difference_in_place(d, m - 1);
  return d;
}

double translational_energy(std::span<const Vec3> p, int m) {
  return sum_squared_norms(position_differences(p, m));
}

double rotational_energy(std::span<const Quat> q, int m) {
  return sum_squared_norms(orientation_differences(q, m));
}

}  // namespace posefair
