// Ellipsoid fit for magnetometer calibration (magnetometer_calibration.hpp), with Eigen's
// least squares and symmetric eigen decomposition.
#include "posefair/core/magnetometer_calibration.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

namespace posefair {

namespace {
constexpr double kMaxRelativeResidual = 0.1;  // of the field strength
constexpr double kMinDirectionSpread = 0.02;  // smallest eigenvalue of E[u u^T] (sphere: 1/3)
}  // namespace

MagnetometerCalibration fit_magnetometer_calibration(std::span<const Vec3> readings) {
  const char* advice = "; turn the sensor through as many orientations as possible while recording";
  if (readings.size() < 9)
    throw std::invalid_argument("magnetometer calibration needs at least 9 readings, got " +
                                std::to_string(readings.size()) + advice);
  // Centre and scale first, so the normal equations are well conditioned in any unit.
  Vec3 mean = Vec3::Zero();
  for (const Vec3& m : readings) {
    if (!m.allFinite()) throw std::invalid_argument("magnetometer calibration: a reading is not finite");
    mean += m;
  }
  mean /= static_cast<double>(readings.size());
  double scale = 0.0;
  for (const Vec3& m : readings) scale = std::max(scale, (m - mean).norm());
  if (!(scale > 0.0)) throw std::invalid_argument(std::string("magnetometer readings do not vary") + advice);

  const Eigen::Index n = static_cast<Eigen::Index>(readings.size());
  Eigen::MatrixXd d(n, 9);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Vec3 p = (readings[static_cast<std::size_t>(k)] - mean) / scale;
    d.row(k) << p.x() * p.x(), p.y() * p.y(), p.z() * p.z(), 2 * p.x() * p.y(), 2 * p.x() * p.z(),
        2 * p.y() * p.z(), 2 * p.x(), 2 * p.y(), 2 * p.z();
  }
  const Eigen::VectorXd u = d.colPivHouseholderQr().solve(Eigen::VectorXd::Ones(n));
  Eigen::Matrix3d a;
  a << u[0], u[3], u[4], u[3], u[1], u[5], u[4], u[5], u[2];
  const Vec3 v(u[6], u[7], u[8]);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> first(a);
  if (first.info() != Eigen::Success || first.eigenvalues().minCoeff() <= 0.0)
    throw std::invalid_argument(std::string("magnetometer readings do not fit an ellipsoid") + advice);
  const Vec3 centre = -a.ldlt().solve(v);
  const double g = 1.0 + centre.dot(a * centre);
  if (!(g > 0.0))
    throw std::invalid_argument(std::string("magnetometer readings do not fit an ellipsoid") + advice);
  const Eigen::Matrix3d shape = a / g;  // (p - c)^T shape (p - c) = 1
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(shape);
  const Vec3 lambda = eig.eigenvalues();
  if (lambda.minCoeff() <= 0.0 || lambda.maxCoeff() > 1e4 * lambda.minCoeff())
    throw std::invalid_argument(std::string("magnetometer readings do not determine an ellipsoid") + advice);

  MagnetometerCalibration cal;
  cal.offset = mean + scale * centre;
  // The ellipsoid's geometric-mean radius, in the readings' unit, is the field strength.
  cal.field_strength = scale * std::pow(lambda.prod(), -1.0 / 6.0);
  cal.soft_iron = eig.eigenvectors() * lambda.cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose() *
                  (cal.field_strength / scale);
  // Judge the fit: the corrected readings must lie near one sphere (a noise cloud at rest
  // also "fits" some small ellipsoid, badly), and their directions must spread in all three
  // axes (covariance of the unit directions: 1/3 each for a fully covered sphere).
  double sum = 0.0;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (const Vec3& m : readings) {
    const Vec3 c = cal.apply(m);
    sum += std::pow(c.norm() - cal.field_strength, 2);
    const Vec3 u = c.normalized();
    spread += u * u.transpose();
  }
  cal.residual_rms = std::sqrt(sum / static_cast<double>(readings.size()));
  spread /= static_cast<double>(readings.size());
  if (cal.residual_rms > kMaxRelativeResidual * cal.field_strength)
    throw std::invalid_argument("magnetometer readings lie on no ellipsoid (corrected norms vary by " +
                                std::to_string(static_cast<int>(100.0 * cal.residual_rms / cal.field_strength)) +
                                " %)" + advice);
  if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread).eigenvalues().minCoeff() < kMinDirectionSpread)
    throw std::invalid_argument(std::string("magnetometer readings cover too few directions") + advice);
  return cal;
}

}  // namespace posefair
