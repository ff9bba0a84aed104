#pragma once
// A magnetometer calibration as text (posefair calibrate writes it, posefair fuse reads it):
//   # posefair magnetometer calibration: corrected = soft_iron * (raw - offset)
//   offset X Y Z
//   soft_iron M11 M12 M13 M21 M22 M23 M31 M32 M33
//   field_strength F
//   residual_rms R
// Lines may come in any order; `#` starts a comment; offset and soft_iron are required.
#include <filesystem>
#include <string>

#include "posefair/core/magnetometer_calibration.hpp"

namespace posefair::formats {

std::string render_magnetometer_calibration(const MagnetometerCalibration& calibration);
// Throws PoseFileError ("<path>:<line>: ...") for a malformed or incomplete file.
MagnetometerCalibration parse_magnetometer_calibration(const std::string& text, const std::string& name);
MagnetometerCalibration read_magnetometer_calibration(const std::filesystem::path& path);

}  // namespace posefair::formats
