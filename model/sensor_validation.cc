#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "model/ray_quantities.h"
#include "model/sensor.h"

// ValidateSensorModel (model/sensor.h): the checks every sensor passes, wherever it comes
// from (a file, a fit, a design).
namespace omnical {

namespace {

std::string Describe(const char* format, double a, double b = 0.0) {
  char text[200];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

// The distortion r (1 + k1 r^2 + k2 r^4) must be monotone, and not nearly flat, wherever it
// is used: up to the undistorted radius of the mirror's outermost point (projection) and up
// to the distorted radius of the image corners (unprojection). Its slope
// 1 + 3 k1 u + 5 k2 u^2 (u = r^2) is a quadratic, so the first u where it drops to
// kMinSlope is found exactly.
std::string CheckDistortion(const PinholeLens<double>& lens, double max_undistorted, double max_distorted) {
  constexpr double kMinSlope = 0.1;  // below this the inverse amplifies errors > 10x
  const double a = 5.0 * lens.k2, b = 3.0 * lens.k1, c = 1.0 - kMinSlope;
  double u_fold = HUGE_VAL;
  if (a == 0.0) {
    if (b < 0.0) u_fold = -c / b;
  } else {
    const double disc = b * b - 4.0 * a * c;
    if (disc >= 0.0) {
      const double root = std::sqrt(disc);
      for (double u : {(-b - root) / (2.0 * a), (-b + root) / (2.0 * a)})
        if (u > 0.0) u_fold = std::min(u_fold, u);
    }
  }
  if (!std::isfinite(u_fold)) return {};
  const double r_fold = std::sqrt(u_fold);
  const double rd_fold = r_fold * (1.0 + u_fold * (lens.k1 + u_fold * lens.k2));
  if (r_fold <= max_undistorted || rd_fold <= max_distorted)
    return Describe("camera.k1: radial distortion (k1, k2) folds or flattens (slope < 0.1) at normalised radius %.4g, "
                    "inside the image or the mirror's image",
                    r_fold);
  return {};
}

// With p1, p2 the distortion is a 2-D map. Its Jacobian is symmetric (the map is a
// gradient), and where it stays positive definite on a disc the map is one-to-one there;
// where its smallest eigenvalue stays >= kMinSlope the inverse amplifies errors at most
// 1 / kMinSlope. Checked on a polar grid over the undistorted disc that reaches the
// mirror's outermost point and whose boundary images outside the image corners' radius
// (so every pixel's preimage lies in it): the disc is grown from the radial preimage of
// the corners until its boundary clears them (the tangential terms pull part of it in).
std::string CheckTangential(const PinholeLens<double>& lens, double max_undistorted, double max_distorted) {
  if (!lens.HasTangential()) return {};
  constexpr double kMinSlope = 0.1;
  constexpr int kRadii = 48, kAzimuths = 96;
  const auto boundary_distorted = [&](double radius) {
    double nearest = HUGE_VAL;
    for (int k = 0; k < kAzimuths; ++k) {
      const double phi = 2.0 * M_PI * k / kAzimuths;
      double distorted_x = 0.0, distorted_y = 0.0;
      lens.Distort(radius * std::cos(phi), radius * std::sin(phi), &distorted_x, &distorted_y);
      nearest = std::min(nearest, std::hypot(distorted_x, distorted_y));
    }
    return nearest;
  };
  double radius = std::max(max_undistorted, lens.UndistortRadius(max_distorted));
  for (int grow = 0; grow < 100 && !(boundary_distorted(radius) >= max_distorted); ++grow) radius *= 1.02;
  for (int i = 1; i <= kRadii; ++i) {
    const double r = radius * i / kRadii;
    for (int k = 0; k < kAzimuths; ++k) {
      const double phi = 2.0 * M_PI * k / kAzimuths;
      const Eigen::Matrix2d jacobian = lens.DistortionJacobian(r * std::cos(phi), r * std::sin(phi));
      const double mean = 0.5 * (jacobian(0, 0) + jacobian(1, 1));
      const double half_gap = std::hypot(0.5 * (jacobian(0, 0) - jacobian(1, 1)), jacobian(0, 1));
      if (!(mean - half_gap >= kMinSlope))
        return Describe("camera.p1: the distortion (k1, k2, p1, p2) folds or flattens (slope < 0.1) at normalised "
                        "radius %.4g, azimuth %.0f deg, inside the image or the mirror's image",
                        r, phi * 180.0 / M_PI);
    }
  }
  if (!(boundary_distorted(radius) >= max_distorted))
    return Describe("camera.p1: the tangential distortion (p1, p2) leaves image corners without a preimage within "
                    "normalised radius %.4g (too large p1, p2?)",
                    radius);
  return {};
}

}  // namespace

std::string ValidateSensorModel(const SensorModel& model) {
  return std::visit(
      [](const auto& m) -> std::string {
        using Model = std::decay_t<decltype(m)>;
        if (std::string why = m.mirror.CheckDomain(m.rim_radius_mm); !why.empty()) return "mirror: " + why;
        if (std::string why = m.lens.CheckDomain(); !why.empty()) return "camera: " + why;
        const Eigen::Matrix3d rotation = m.pose.CameraFromMirrorRotation();
        const Eigen::Vector3d translation = m.pose.CameraFromMirrorTranslation();
        const Eigen::Vector3d lens_in_mirror = -(rotation.transpose() * translation);
        const Eigen::Vector3d lens_direction = -rotation.row(2).transpose();  // orthographic
        const double r2_lens = lens_in_mirror.head<2>().squaredNorm();
        if (r2_lens < m.rim_radius_mm * m.rim_radius_mm && !(lens_in_mirror.z() < m.mirror.EvaluateSag(r2_lens).z))
          return "pose.m: the lens centre lies inside the mirror (m too small for this tilt/decenter)";
        // The solvers need (1) a mirror convex towards the camera: z' > 0 and z'' > 0 out to the
        // rim (unique reflection point, monotone Omega); (2) seen from its front all the way to
        // the rim: the lens on the outer side of every tangent plane (else the rim zone is the
        // hidden back of the surface); (3) in front of the lens.
        constexpr int kRadii = 400;
        const int azimuths = m.IsAxial() ? 1 : 72;
        // Plain scalars, not Eigen objects, in the loop below: a tilted sensor takes 28,800
        // samples, and the sanitizer and fuzzing builds (Eigen barely inlined) load sensors by
        // the thousand.
        const double r00 = rotation(0, 0), r01 = rotation(0, 1), r02 = rotation(0, 2), t_x = translation.x();
        const double r10 = rotation(1, 0), r11 = rotation(1, 1), r12 = rotation(1, 2), t_y = translation.y();
        const double r20 = rotation(2, 0), r21 = rotation(2, 1), r22 = rotation(2, 2), t_z = translation.z();
        const double toward_x = Model::kOrthographic ? lens_direction.x() : lens_in_mirror.x();
        const double toward_y = Model::kOrthographic ? lens_direction.y() : lens_in_mirror.y();
        const double toward_z = Model::kOrthographic ? lens_direction.z() : lens_in_mirror.z();
        double max_tan = 0.0;
        for (int i = 1; i <= kRadii; ++i) {
          const double r = m.rim_radius_mm * i / kRadii;
          const SagDerivatives<double> sag = m.mirror.EvaluateSag(r * r);
          double slope = 0.0, curvature = 0.0;
          RadialSlopes(sag, r, &slope, &curvature);
          if (!(sag.dz_ds > 0.0) || !(curvature > 0.0))
            return Describe("mirror: the profile is not convex towards the camera at r = %.4g mm (z' = %.3g): "
                            "omnical's solvers need z' > 0 and z'' > 0 out to the rim",
                            r, slope);
          for (int k = 0; k < azimuths; ++k) {
            const double phi = 2.0 * M_PI * k / azimuths;
            const double cos_phi = std::cos(phi), sin_phi = std::sin(phi);
            const double x = r * cos_phi, y = r * sin_phi, z = sag.z;
            const double normal_x = slope * cos_phi, normal_y = slope * sin_phi;  // outward normal (., ., -1)
            const double facing = Model::kOrthographic
                                      ? toward_x * normal_x + toward_y * normal_y - toward_z
                                      : (toward_x - x) * normal_x + (toward_y - y) * normal_y - (toward_z - z);
            if (!(facing > 0.0))
              return Describe("mirror.rim_radius: the lens sees the mirror edge-on at r = %.4g mm, before the rim "
                              "(azimuth %.0f deg): rim_radius too large for this profile and pose",
                              r, phi * 180.0 / M_PI);
            const double camera_x = r00 * x + r01 * y + r02 * z + t_x;
            const double camera_y = r10 * x + r11 * y + r12 * z + t_y;
            const double camera_z = r20 * x + r21 * y + r22 * z + t_z;
            if (!(camera_z > 0.0))
              return Describe("pose: part of the mirror lies behind the lens plane (r = %.4g mm, azimuth %.0f deg)", r,
                              phi * 180.0 / M_PI);
            max_tan = std::max(max_tan, std::sqrt(camera_x * camera_x + camera_y * camera_y) / camera_z);
          }
        }
        if constexpr (!Model::kOrthographic) {
          const double corner_u = std::max(std::abs(m.lens.cx_px + 0.5), std::abs(m.image_width_px - 0.5 - m.lens.cx_px));
          const double corner_v = std::max(std::abs(m.lens.cy_px + 0.5), std::abs(m.image_height_px - 0.5 - m.lens.cy_px));
          const double max_distorted = std::hypot(corner_u / m.lens.fx_px, corner_v / m.lens.fy_px);
          if (std::string why = CheckDistortion(m.lens, max_tan, max_distorted); !why.empty()) return why;
          if (std::string why = CheckTangential(m.lens, max_tan, max_distorted); !why.empty()) return why;
        }
        return {};
      },
      model);
}

}  // namespace omnical
