// The seed paper's ray quantities for an axial sensor (Ohte & Tsuzuki Eqs. 1-6), in its
// cross-section: mirror frame, lens principal point at (0, -m), angles in radians.
#pragma once

#include <cmath>

#include "model/catadioptric.h"

namespace omnical {

struct AxialRayQuantities {
  double x_mm;            // radius of the reflection point P
  double z_mm;            // z_p = f(x_p)                                  (Eq. 1)
  double beta_rad;        // mirror slope, tan(beta) = dz/dx                (Eq. 2)
  double theta_rad;       // lens viewing angle, tan(theta) = x/(m + z)    (Eq. 5); 0 orthographic
  double gamma_rad;       // angle of incidence = reflection, beta + theta (Eq. 3)
  double omega_rad;       // object ray from the -z axis, 2 beta + theta   (Eq. 4)
  double viewpoint_z_mm;  // where the object ray crosses the axis, z_p + x_p / tan(Omega) (Eq. 6)
};

template <template <typename> class Profile, template <typename> class Lens>
AxialRayQuantities ComputeAxialRay(const Catadioptric<double, Profile, Lens>& sensor, double x_mm) {
  const SagDerivatives<double> sag = sensor.mirror.EvaluateSag(x_mm * x_mm);
  double slope = 0.0, curvature = 0.0;
  RadialSlopes(sag, x_mm, &slope, &curvature);
  AxialRayQuantities q;
  q.x_mm = x_mm;
  q.z_mm = sag.z;
  q.beta_rad = std::atan(slope);
  q.theta_rad = Lens<double>::kIsOrthographic ? 0.0 : std::atan2(x_mm, sensor.pose.m_mm + sag.z);
  q.gamma_rad = q.beta_rad + q.theta_rad;
  q.omega_rad = 2.0 * q.beta_rad + q.theta_rad;
  // On the axis the viewpoint is the paraxial limit: x / tan(Omega) -> 1 / Omega'(0).
  if (x_mm > 0.0) {
    q.viewpoint_z_mm = sag.z + x_mm / std::tan(q.omega_rad);
  } else {
    const double domega_dx = 4.0 * sag.dz_ds + (Lens<double>::kIsOrthographic ? 0.0 : 1.0 / sensor.pose.m_mm);
    q.viewpoint_z_mm = 1.0 / domega_dx;
  }
  return q;
}

}  // namespace omnical
