// The reflection condition for a tilted or decentred mirror (NONCENTRAL-NOTES):
// the reflection point M = (x, y, f(x^2 + y^2)) makes the optical path
// L = |C - M| + |P - M| stationary (a minimum on a convex mirror). With u1, u2 the unit
// vectors from M to the lens and to the point and T_x, T_y the surface tangents,
//   F = [(u1 + u2) . T_x, (u1 + u2) . T_y] = -grad L = 0.
// An orthographic lens has its centre at infinity: u1 is the constant direction
// towards the lens and |C - M| becomes -u1 . M (plus a constant).
#pragma once

#include <cmath>

#include "model/mirror_profiles.h"
#include "model/types.h"

namespace omnical {

struct FermatReflection {
  double f_x, f_y;           // F
  double j_xx, j_xy, j_yy;   // dF/d(x, y), symmetric, = -Hessian of L
  double path_length;        // L (up to a constant for an orthographic lens)
  double z;                  // sag at (x, y)
  double slope_x, slope_y;   // dz/dx, dz/dy: the outward normal is (slope_x, slope_y, -1)
};

// Plain scalars (no Eigen) so the batch loops vectorise. lens is the lens centre
// (pinhole) or, for an orthographic lens, the unit direction from the mirror towards
// the lens; point is the scene point; both in the mirror frame.
template <bool kOrthographic, typename Profile>
inline FermatReflection EvaluateFermatReflection(double lens_x, double lens_y, double lens_z, const Profile& mirror,
                                                 double point_x, double point_y, double point_z, double x,
                                                 double y) {
  const SagDerivatives<double> sag = mirror.EvaluateSag(x * x + y * y);
  const double fx = 2.0 * x * sag.dz_ds, fy = 2.0 * y * sag.dz_ds;
  const double fxx = 2.0 * sag.dz_ds + 4.0 * x * x * sag.d2z_ds2;
  const double fxy = 4.0 * x * y * sag.d2z_ds2;
  const double fyy = 2.0 * sag.dz_ds + 4.0 * y * y * sag.d2z_ds2;
  double u1x, u1y, u1z, inv_l1, l1;
  if constexpr (kOrthographic) {
    u1x = lens_x, u1y = lens_y, u1z = lens_z;
    inv_l1 = 0.0;
    l1 = -(lens_x * x + lens_y * y + lens_z * sag.z);
  } else {
    u1x = lens_x - x, u1y = lens_y - y, u1z = lens_z - sag.z;
    l1 = std::sqrt(u1x * u1x + u1y * u1y + u1z * u1z);
    inv_l1 = 1.0 / l1;
    u1x *= inv_l1, u1y *= inv_l1, u1z *= inv_l1;
  }
  double u2x = point_x - x, u2y = point_y - y, u2z = point_z - sag.z;
  const double l2 = std::sqrt(u2x * u2x + u2y * u2y + u2z * u2z);
  const double inv_l2 = 1.0 / l2;
  u2x *= inv_l2, u2y *= inv_l2, u2z *= inv_l2;
  // Tangents T_x = (1, 0, fx), T_y = (0, 1, fy).
  const double a1x = u1x + u1z * fx, a1y = u1y + u1z * fy;
  const double a2x = u2x + u2z * fx, a2y = u2y + u2z * fy;
  const double txx = 1.0 + fx * fx, txy = fx * fy, tyy = 1.0 + fy * fy;
  const double uz = u1z + u2z;
  FermatReflection out;
  out.f_x = a1x + a2x;
  out.f_y = a1y + a2y;
  out.j_xx = -(txx - a1x * a1x) * inv_l1 - (txx - a2x * a2x) * inv_l2 + uz * fxx;
  out.j_xy = -(txy - a1x * a1y) * inv_l1 - (txy - a2x * a2y) * inv_l2 + uz * fxy;
  out.j_yy = -(tyy - a1y * a1y) * inv_l1 - (tyy - a2y * a2y) * inv_l2 + uz * fyy;
  out.path_length = l1 + l2;
  out.z = sag.z;
  out.slope_x = fx;
  out.slope_y = fy;
  return out;
}

// The Newton step -J^-1 F when -J (the Hessian of L) is positive definite, i.e. when
// the step descends towards the minimum of L; false otherwise.
inline bool FermatNewtonStep(const FermatReflection& e, double* step_x, double* step_y) {
  const double det = e.j_xx * e.j_yy - e.j_xy * e.j_xy;
  *step_x = -(e.j_yy * e.f_x - e.j_xy * e.f_y) / det;
  *step_y = -(-e.j_xy * e.f_x + e.j_xx * e.f_y) / det;
  return (e.j_xx < 0.0) & (det > 0.0);
}

// F alone in any scalar type: the Jet pass of the implicit-function step. Same
// conventions as EvaluateFermatReflection.
template <bool kOrthographic, typename T, typename Profile>
Vec2<T> FermatResidual(const Vec3<T>& lens, const Profile& mirror, const Vec3<T>& point, const T& x, const T& y) {
  const SagDerivatives<T> sag = mirror.EvaluateSag(x * x + y * y);
  const T fx = T(2.0) * x * sag.dz_ds, fy = T(2.0) * y * sag.dz_ds;
  const Vec3<T> m(x, y, sag.z);
  Vec3<T> u1 = lens;
  if constexpr (!kOrthographic) u1 = (lens - m).normalized();
  const Vec3<T> u = u1 + (point - m).normalized();
  return Vec2<T>(u.x() + u.z() * fx, u.y() + u.z() * fy);
}

}  // namespace omnical
