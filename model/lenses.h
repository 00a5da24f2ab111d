// Lenses looking at the mirror, in the camera frame (model/types.h).
//
// Every lens has the interface listed at the top of model/model_registry.h, where lenses
// are registered (how to add one is written there).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <type_traits>

#include "model/parameter_field.h"
#include "model/scalar.h"
#include "model/types.h"

namespace omnical {

// Pinhole with OpenCV's radial (k1, k2) and tangential (p1, p2) distortion:
// x' = x (1 + k1 r^2 + k2 r^4) + 2 p1 x y + p2 (r^2 + 2 x^2),
// y' = y (1 + k1 r^2 + k2 r^4) + p1 (r^2 + 2 y^2) + 2 p2 x y,
// r^2 = x^2 + y^2, x = X / Z; u = fx x' + cx. Valid for Z > 0 and, for unprojection, where
// the distortion is one-to-one (checked over the image by the sensor reader: the radial
// part monotone; with p1, p2 also the whole map's Jacobian, model/sensor_validation.cc).
// p1, p2 model a decentred lens element; the fit holds them unless asked or chosen by
// held-out folds (calib/tangential_choice.h): through the lens's narrow view of the mirror
// their image shift trades with the mirror's decenter and the principal point.
template <typename T>
struct PinholeLens {
  static constexpr const char* kName = "pinhole";
  static constexpr int kNumParams = 8;
  static constexpr std::array<ParameterField, kNumParams> kFields{
      {ScalarField("fx", "fx_px", ParameterGroup::kFocal, true, FieldDomain::kPositive, 1e8),
       ScalarField("fy", "fy_px", ParameterGroup::kFocal, true, FieldDomain::kPositive, 1e8),
       ScalarField("cx", "cx_px", ParameterGroup::kPrincipalPoint, false, FieldDomain::kBounded, 1e7),
       ScalarField("cy", "cy_px", ParameterGroup::kPrincipalPoint, false, FieldDomain::kBounded, 1e7),
       ScalarField("k1", "k1", ParameterGroup::kDistortion, false, FieldDomain::kBounded, 1e6, 0, true),
       ScalarField("k2", "k2", ParameterGroup::kDistortion, false, FieldDomain::kBounded, 1e6, 0, true),
       // Written only when not 0: files without them read the same in older versions.
       OmittedWhenZero(
           ScalarField("p1", "p1", ParameterGroup::kTangential, false, FieldDomain::kBounded, 1.0, 0, true)),
       OmittedWhenZero(
           ScalarField("p2", "p2", ParameterGroup::kTangential, false, FieldDomain::kBounded, 1.0, 0, true))}};
  static constexpr bool kIsOrthographic = false;
  T fx_px, fy_px, cx_px, cy_px, k1, k2, p1, p2;

  // The distorted normalised point (x', y') of an undistorted one (x, y).
  void Distort(const T& x, const T& y, T* distorted_x, T* distorted_y) const {
    const T r2 = x * x + y * y;
    const T radial = T(1.0) + r2 * (k1 + r2 * k2);
    *distorted_x = x * radial + T(2.0) * p1 * x * y + p2 * (r2 + T(2.0) * x * x);
    *distorted_y = y * radial + p1 * (r2 + T(2.0) * y * y) + T(2.0) * p2 * x * y;
  }

  // Valid in front of the lens (Z > 0). The pixel is written either way (without a
  // branch, so the batch loops vectorise); callers ignore it when false is returned.
  bool ProjectToPixel(const Vec3<T>& point_in_camera, Vec2<T>* pixel) const {
    const T x = point_in_camera.x() / point_in_camera.z();
    const T y = point_in_camera.y() / point_in_camera.z();
    T distorted_x, distorted_y;
    Distort(x, y, &distorted_x, &distorted_y);
    (*pixel)(0) = fx_px * distorted_x + cx_px;
    (*pixel)(1) = fy_px * distorted_y + cy_px;
    return ScalarPart(point_in_camera.z()) > 0.0;
  }

  bool HasTangential() const { return ScalarPart(p1) != 0.0 || ScalarPart(p2) != 0.0; }

  // d(x', y') / d(x, y) at an undistorted point, in double.
  Eigen::Matrix2d DistortionJacobian(double x, double y) const {
    const double a = ScalarPart(k1), b = ScalarPart(k2), t1 = ScalarPart(p1), t2 = ScalarPart(p2);
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (a + r2 * b);
    const double radial_slope = 2.0 * (a + 2.0 * b * r2);  // d radial / d(x or y), over x or y
    Eigen::Matrix2d jacobian;
    jacobian << radial + radial_slope * x * x + 2.0 * t1 * y + 6.0 * t2 * x,
        radial_slope * x * y + 2.0 * t1 * x + 2.0 * t2 * y,
        radial_slope * x * y + 2.0 * t1 * x + 2.0 * t2 * y,
        radial + radial_slope * y * y + 6.0 * t1 * y + 2.0 * t2 * x;
    return jacobian;
  }
  // J^-1 v for that Jacobian; v may be a Jet's (its derivative parts are carried through).
  template <typename U>
  static Vec2<U> SolveJacobian(const Eigen::Matrix2d& jacobian, const Vec2<U>& vector) {
    const double det = jacobian(0, 0) * jacobian(1, 1) - jacobian(0, 1) * jacobian(1, 0);
    return Vec2<U>((jacobian(1, 1) * vector(0) - jacobian(0, 1) * vector(1)) / det,
                   (jacobian(0, 0) * vector(1) - jacobian(1, 0) * vector(0)) / det);
  }

  // Undistorted radius r for a distorted radius rd: safeguarded Newton on
  // F(r) = r (1 + k1 r^2 + k2 r^4) = rd in double (bracket grown from rd, bisection when a
  // step leaves it; the sensor reader guarantees F is monotone with slope >= 0.1 where it
  // is used), then one Newton step in T (implicit-function derivative for Jets).
  T UndistortRadius(const T& distorted_radius) const {
    const double rd = ScalarPart(distorted_radius);
    const double a = ScalarPart(k1), b = ScalarPart(k2);
    auto f = [&](double r) { return r * (1.0 + r * r * (a + r * r * b)) - rd; };
    auto slope_at = [&](double r) { return 1.0 + r * r * (3.0 * a + 5.0 * r * r * b); };
    double lo = 0.0, hi = std::max(rd, 1e-300);
    for (int grow = 0; grow < 60 && f(hi) < 0.0; ++grow) lo = hi, hi *= 2.0;
    double r = std::min(std::max(rd, lo), hi);
    for (int iteration = 0; iteration < 100; ++iteration) {
      const double value = f(r);
      if (value < 0.0) lo = r; else hi = r;
      double next = r - value / slope_at(r);
      // As in the mirror solvers: a converged step is taken before the bracket test, which
      // a step of one rounding error at the bracket's end would fail.
      const bool converged = std::abs(next - r) <= 1e-15 * (1.0 + r);
      if (!converged && !(next > lo && next < hi)) next = 0.5 * (lo + hi);
      r = next;
      if (converged || hi - lo <= 1e-15 * (1.0 + r)) break;
    }
    if constexpr (std::is_same_v<T, double>) {
      return r;
    } else {
      const T rt(r);
      const T residual = rt * (T(1.0) + rt * rt * (k1 + rt * rt * k2)) - distorted_radius;
      return rt - residual / slope_at(r);
    }
  }

  // Undistorted point of a distorted one with p1, p2: Newton on the 2-D map in double from
  // the radial solution, each step halved until the residual falls (the sensor reader
  // guarantees the map one-to-one with a well-conditioned Jacobian over the image), then
  // one Newton step in T (the implicit-function derivative for Jets, as for the radius).
  Vec2<T> UndistortPoint(const T& distorted_x, const T& distorted_y) const {
    const PinholeLens<double> lens = Cast<double>();
    const Eigen::Vector2d target(ScalarPart(distorted_x), ScalarPart(distorted_y));
    const double radius = target.norm();
    Eigen::Vector2d point = target;
    if (radius > 0.0) point *= lens.UndistortRadius(radius) / radius;
    auto residual_at = [&](const Eigen::Vector2d& p) {
      Eigen::Vector2d distorted;
      lens.Distort(p.x(), p.y(), &distorted.x(), &distorted.y());
      return Eigen::Vector2d(distorted - target);
    };
    Eigen::Vector2d residual = residual_at(point);
    for (int iteration = 0; iteration < 50 && residual.norm() > 1e-15 * (1.0 + radius); ++iteration) {
      const Eigen::Vector2d step = SolveJacobian(lens.DistortionJacobian(point.x(), point.y()), residual);
      double fraction = 1.0;
      Eigen::Vector2d next = point - step, next_residual = residual_at(next);
      for (int halving = 0; halving < 30 && !(next_residual.norm() < residual.norm()); ++halving) {
        fraction *= 0.5;
        next = point - fraction * step;
        next_residual = residual_at(next);
      }
      if (!(next_residual.norm() < residual.norm())) break;  // at rounding level
      point = next, residual = next_residual;
    }
    if constexpr (std::is_same_v<T, double>) {
      return point;
    } else {
      const Vec2<T> at(T(point.x()), T(point.y()));
      Vec2<T> distorted;
      Distort(at(0), at(1), &distorted(0), &distorted(1));
      // With J in double: the Jets' derivative parts are carried by the error.
      const Vec2<T> error(distorted(0) - distorted_x, distorted(1) - distorted_y);
      return at - SolveJacobian(lens.DistortionJacobian(point.x(), point.y()), error);
    }
  }

  // Ray through the lens centre for a pixel: origin 0, unit direction.
  void PixelToRay(const Vec2<T>& pixel, Vec3<T>* origin, Vec3<T>* direction) const {
    using std::sqrt;
    const T xd = (pixel(0) - cx_px) / fx_px;
    const T yd = (pixel(1) - cy_px) / fy_px;
    Vec3<T> ray(xd, yd, T(1.0));
    // Jets take the 2-D solve even where p1 = p2 = 0: the radial one has no derivative in them.
    if (HasTangential() || !std::is_same_v<T, double>) {
      ray.template head<2>() = UndistortPoint(xd, yd);
    } else if (const T rd2 = xd * xd + yd * yd; ScalarPart(rd2) > 0.0) {
      const T rd = sqrt(rd2);
      const T scale = UndistortRadius(rd) / rd;
      ray(0) *= scale, ray(1) *= scale;
    }
    *origin = Vec3<T>::Zero();
    *direction = ray / ray.norm();
  }

  // Largest focal length, px: converts a length tolerance into a pixel tolerance.
  double MaxFocalPx() const { return std::max(ScalarPart(fx_px), ScalarPart(fy_px)); }

  std::string CheckDomain() const {
    if (!(ScalarPart(fx_px) > 0.0) || !(ScalarPart(fy_px) > 0.0)) return "fx and fy must be > 0";
    if (ScalarPart(fx_px) < 1e-3 || ScalarPart(fy_px) < 1e-3) return "fx: focal lengths below 1e-3 px are not a camera";
    return {};
  }
  template <typename U>
  PinholeLens<U> Cast() const {
    return {CastScalar<U>(fx_px), CastScalar<U>(fy_px), CastScalar<U>(cx_px), CastScalar<U>(cy_px),
            CastScalar<U>(k1),    CastScalar<U>(k2),    CastScalar<U>(p1),    CastScalar<U>(p2)};
  }
  static PinholeLens FromParams(const T* p) { return {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]}; }
  void ToParams(T* p) const {
    p[0] = fx_px; p[1] = fy_px; p[2] = cx_px; p[3] = cy_px; p[4] = k1; p[5] = k2; p[6] = p1; p[7] = p2;
  }
};

// Orthographic (telecentric) lens: every ray is parallel to the optical axis.
// u = s X + cx, v = s Y + cy with s in px per mm.
template <typename T>
struct OrthographicLens {
  static constexpr const char* kName = "orthographic";
  static constexpr int kNumParams = 3;
  static constexpr std::array<ParameterField, kNumParams> kFields{
      {ScalarField("scale_px_per_mm", "scale_px_per_mm", ParameterGroup::kFocal, true, FieldDomain::kPositive, 1e6),
       ScalarField("cx", "cx_px", ParameterGroup::kPrincipalPoint, false, FieldDomain::kBounded, 1e7),
       ScalarField("cy", "cy_px", ParameterGroup::kPrincipalPoint, false, FieldDomain::kBounded, 1e7)}};
  static constexpr bool kIsOrthographic = true;
  T scale_px_per_mm, cx_px, cy_px;

  // Valid in front of the lens plane (Z > 0), where its rays come from. The pixel is
  // written either way, as the pinhole's is.
  bool ProjectToPixel(const Vec3<T>& point_in_camera, Vec2<T>* pixel) const {
    (*pixel)(0) = scale_px_per_mm * point_in_camera.x() + cx_px;
    (*pixel)(1) = scale_px_per_mm * point_in_camera.y() + cy_px;
    return ScalarPart(point_in_camera.z()) > 0.0;
  }
  void PixelToRay(const Vec2<T>& pixel, Vec3<T>* origin, Vec3<T>* direction) const {
    *origin = Vec3<T>((pixel(0) - cx_px) / scale_px_per_mm, (pixel(1) - cy_px) / scale_px_per_mm, T(0.0));
    *direction = Vec3<T>(T(0.0), T(0.0), T(1.0));
  }
  double MaxFocalPx() const { return ScalarPart(scale_px_per_mm); }
  std::string CheckDomain() const {
    if (!(ScalarPart(scale_px_per_mm) > 0.0)) return "scale_px_per_mm must be > 0";
    return {};
  }
  template <typename U>
  OrthographicLens<U> Cast() const {
    return {CastScalar<U>(scale_px_per_mm), CastScalar<U>(cx_px), CastScalar<U>(cy_px)};
  }
  static OrthographicLens FromParams(const T* p) { return {p[0], p[1], p[2]}; }
  void ToParams(T* p) const {
    p[0] = scale_px_per_mm; p[1] = cx_px; p[2] = cy_px;
  }
};

}  // namespace omnical
