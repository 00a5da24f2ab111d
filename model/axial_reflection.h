// The reflection condition of an axial sensor in its cross-section (NONCENTRAL-NOTES,
// seed Eqs. 2-6), written without trigonometry.
//
// In the plane through the axis and the point, with x the radius of the reflection
// point M = (x, f(x)) and P = (rho, h) the point, the lens ray d runs from the lens to
// M: d = (x, m + f) for a pinhole at (0, -m), d = (0, 1) for an orthographic lens. With
// n = (f', -1) the surface normal, the reflected (outgoing) direction is
// r = d - 2 (d.n) n / |n|^2, and P lies on that ray when
//   G(x) = r_x (h - f) - r_z (rho - x) = 0,     (P - M) . r > 0.
// G(0) = m rho > 0; for a convex mirror G changes sign once on [0, rim] when P is seen.
#pragma once

#include "model/mirror_profiles.h"

namespace omnical {

// G and dG/dx in double, plus the reflected direction (unnormalised) for the checks.
struct AxialReflection {
  double g;
  double dg_dx;
  double r_x;
  double r_z;
  double sag_mm;
};

// sag holds g(s), g', g'' at s = x^2 (see mirror_profiles.h).
inline AxialReflection EvaluateAxialReflection(bool orthographic, double m_mm, double x,
                                               const SagDerivatives<double>& sag, double rho,
                                               double h) {
  const double f = sag.z;
  const double fp = 2.0 * x * sag.dz_ds;
  const double fpp = 2.0 * sag.dz_ds + 4.0 * x * x * sag.d2z_ds2;
  const double d_x = orthographic ? 0.0 : x;
  const double d_z = orthographic ? 1.0 : m_mm + f;
  const double dd_x = orthographic ? 0.0 : 1.0;
  const double dd_z = orthographic ? 0.0 : fp;
  const double s = d_x * fp - d_z;
  const double ds = dd_x * fp + d_x * fpp - dd_z;
  const double inv_k = 1.0 / (1.0 + fp * fp);
  const double q = 2.0 * s * inv_k;
  const double dq = 2.0 * (ds - s * 2.0 * fp * fpp * inv_k) * inv_k;
  const double r_x = d_x - q * fp;
  const double r_z = d_z + q;
  const double dr_x = dd_x - dq * fp - q * fpp;
  const double dr_z = dd_z + dq;
  const double g = r_x * (h - f) - r_z * (rho - x);
  const double dg = dr_x * (h - f) - r_x * fp - dr_z * (rho - x) + r_z;
  return {g, dg, r_x, r_z, f};
}

}  // namespace omnical
