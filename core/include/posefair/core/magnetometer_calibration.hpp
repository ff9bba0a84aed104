#pragma once
// Hard- and soft-iron magnetometer calibration from a recording (docs/fusion.md): readings
// taken while the sensor turns through many orientations lie on an ellipsoid
// (m - b)^T A (m - b) = 1 instead of a sphere around zero. A least-squares fit of the general
// quadric x^T A x + 2 v^T x = 1 gives the hard-iron offset b = -A⁻¹v and, from A, the
// soft-iron matrix W (symmetric, the square root of A scaled to the field strength) so that
// the corrected reading W (m - b) has the same norm in every orientation.
#include <cstddef>
#include <span>
#include <stdexcept>

#include "posefair/core/so3.hpp"

namespace posefair {

struct MagnetometerCalibration {
  Vec3 offset = Vec3::Zero();                          // hard iron b, same unit as the readings
  Eigen::Matrix3d soft_iron = Eigen::Matrix3d::Identity();  // W
  double field_strength = 0.0;                         // |W (m - b)|, the readings' unit
  double residual_rms = 0.0;                           // RMS of |W (m - b)| - field_strength

  Vec3 apply(const Vec3& m) const { return soft_iron * (m - offset); }
};

// Throws std::invalid_argument when the readings do not determine an ellipsoid (fewer than 9
// readings, non-finite ones, a quadric that is not an ellipsoid, corrected norms that vary by
// more than 10 %, or directions that do not spread in all three axes), with a message saying
// to turn the sensor through more orientations.
MagnetometerCalibration fit_magnetometer_calibration(std::span<const Vec3> readings);

}  // namespace posefair
