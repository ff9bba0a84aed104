#pragma once
// Rodrigues, Silva Leite & Jakubiak's Figure 6: one natural spline segment on S² between
// p_i and p_{i+1} with velocities v_i, v_{i+1}. The printed v_{i+1} = (1/10, 9/5, (9√3 − 1)/15) is
// not tangent at p_{i+1} (p·v = 0.1); with first component −1/10 it is (ERRATA item 3).
#include <cmath>

#include "posefair/core/sphere_geometric_spline.hpp"

namespace posefair::geometric_splines {

struct Figure6Data {
  SpherePoint<3> p0, p1, v0, v1_printed, v1_corrected;
};

inline Figure6Data figure6_data() {
  const double r3 = std::sqrt(3.0);
  return {SpherePoint<3>(r3 / 2, -r3 / 4, 0.25), SpherePoint<3>(0.5, r3 / 4, -0.75), SpherePoint<3>(0.5, r3, 3 - r3),
          SpherePoint<3>(0.1, 1.8, (9 * r3 - 1) / 15), SpherePoint<3>(-0.1, 1.8, (9 * r3 - 1) / 15)};
}

}  // namespace posefair::geometric_splines
