#include "model/optics.h"

#include "model/minimize_1d.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace omnical {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

// Eq. 14 / 18 in curvature form, so flat directions (curvature 0) need no special case:
// 1/q = 2 kappa_t / cos(gamma) + 1/p (tangential), 2 kappa_s cos(gamma) + 1/p (sagittal).
VirtualImage VirtualImageAt(const AxialRayQuantities& ray, double m_mm, double inverse_q) {
  VirtualImage image;
  image.distance_mm = 1.0 / inverse_q;
  image.x_mm = ray.x_mm + image.distance_mm * std::sin(ray.theta_rad);  // Eqs. 15 / 19
  image.z_mm = ray.z_mm + image.distance_mm * std::cos(ray.theta_rad);  // Eqs. 16 / 20
  image.lens_distance_mm = m_mm + image.z_mm;                          // Eqs. 34 / 35
  return image;
}

template <typename Model>
FieldSample AnalyzeSample(const Model& model, double x, double near_distance_mm) {
  FieldSample sample;
  const AxialRayQuantities ray = ComputeAxialRay(model, x);
  sample.ray = ray;
  double fp = 0.0, fpp = 0.0;
  RadialSlopes(model.mirror.EvaluateSag(x * x), x, &fp, &fpp);
  const double m = model.pose.m_mm;
  double dh_dx = 0.0, dtheta_dx = 0.0;
  if constexpr (Model::kOrthographic) {
    sample.h_px = model.lens.scale_px_per_mm * x;
    dh_dx = model.lens.scale_px_per_mm;
  } else {
    // Eq. 7, h = b tan(theta), with the lens's radial distortion along the x axis. Its
    // tangential terms (a decentred lens) are left out: the seed's characteristics are
    // those of the rotationally symmetric design.
    const double depth = m + ray.z_mm;
    const double t = x / depth;
    const double dt_dx = (depth - x * fp) / (depth * depth);
    const double t2 = t * t;
    sample.h_px = model.lens.fx_px * t * (1.0 + t2 * (model.lens.k1 + t2 * model.lens.k2));
    dh_dx = model.lens.fx_px * (1.0 + t2 * (3.0 * model.lens.k1 + 5.0 * t2 * model.lens.k2)) * dt_dx;
    dtheta_dx = dt_dx / (1.0 + t2);
  }
  const double domega_dx = 2.0 * fpp / (1.0 + fp * fp) + dtheta_dx;  // d(2 beta + theta)/dx
  // Envelope of the rays P(x) + t (sin Omega, -cos Omega): cross(P' + t r', r) = 0 with
  // P' = (1, f') and r' = Omega' (cos Omega, sin Omega) gives t = -(cos Omega + f' sin Omega) / Omega'.
  const double t_caustic = -(std::cos(ray.omega_rad) + fp * std::sin(ray.omega_rad)) / domega_dx;
  sample.caustic_x_mm = x + t_caustic * std::sin(ray.omega_rad);
  sample.caustic_z_mm = ray.z_mm - t_caustic * std::cos(ray.omega_rad);
  sample.dh_domega_px_per_rad = dh_dx / domega_dx;                    // Eq. 8
  sample.delta_h_px = sample.dh_domega_px_per_rad / kDegPerRad;       // Eq. 9
  sample.delta_w_px = sample.h_px / (kDegPerRad * std::sin(ray.omega_rad));  // Eq. 10
  sample.delta_s_px2 = sample.delta_h_px * sample.delta_w_px;         // Eq. 11
  sample.aspect_ratio = sample.delta_w_px / sample.delta_h_px;        // Eq. 12
  const double slope_norm = std::sqrt(1.0 + fp * fp);
  sample.tangential_curvature_per_mm = fpp / (slope_norm * slope_norm * slope_norm);  // 1/R_t, Eq. 13
  sample.sagittal_curvature_per_mm = fp / (x * slope_norm);                          // 1/R_s, Eq. 17
  const double cos_gamma = std::cos(ray.gamma_rad);
  const double kt = 2.0 * sample.tangential_curvature_per_mm / cos_gamma;
  const double ks = 2.0 * sample.sagittal_curvature_per_mm * cos_gamma;
  sample.tangential_far = VirtualImageAt(ray, m, kt);
  sample.sagittal_far = VirtualImageAt(ray, m, ks);
  sample.tangential_near = VirtualImageAt(ray, m, kt + 1.0 / near_distance_mm);
  sample.sagittal_near = VirtualImageAt(ray, m, ks + 1.0 / near_distance_mm);
  return sample;
}

// Solid-angle weight sin(Omega) dOmega of each sample (trapezoid in Omega).
std::vector<double> SolidAngleWeights(const std::vector<FieldSample>& field) {
  const size_t n = field.size();
  std::vector<double> weights(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const double lo = field[i == 0 ? 0 : i - 1].ray.omega_rad;
    const double hi = field[i + 1 == n ? i : i + 1].ray.omega_rad;
    weights[i] = std::sin(field[i].ray.omega_rad) * std::abs(hi - lo) * 0.5;
  }
  return weights;
}

}  // namespace

Sensor AlignedCounterpart(const Sensor& sensor) {
  SensorModel model = sensor.model();
  std::visit(
      [](auto& m) {
        m.pose.tilt_x_rad = m.pose.tilt_y_rad = 0.0;
        m.pose.decenter_x_mm = m.pose.decenter_y_mm = 0.0;
      },
      model);
  return Sensor(model);
}

std::vector<FieldSample> AnalyzeField(const Sensor& sensor, int samples, double near_distance_mm) {
  if (samples < 2) throw std::invalid_argument("AnalyzeField needs at least 2 samples");
  std::vector<FieldSample> field;
  field.reserve(samples);
  std::visit(
      [&](const auto& model) {
        for (int i = 1; i <= samples; ++i)
          field.push_back(AnalyzeSample(model, model.rim_radius_mm * i / samples, near_distance_mm));
      },
      AlignedCounterpart(sensor).model());
  return field;
}

double BlurDiameterMm(const BlurSettings& lens, double lens_distance_mm, double focus_distance_mm) {
  const double f = lens.lens_focal_mm;
  return (f * f / lens.f_number) * (lens_distance_mm - focus_distance_mm) /
         ((focus_distance_mm - f) * lens_distance_mm);  // Eq. 28
}

double DepthOfFieldMm(const BlurSettings& lens, double focus_distance_mm) {
  const double f2 = lens.lens_focal_mm * lens.lens_focal_mm;
  const double spread = lens.pixel_mm * lens.f_number * focus_distance_mm;
  if (spread >= f2) return std::numeric_limits<double>::infinity();  // beyond the hyperfocal distance
  const double far = f2 * focus_distance_mm / (f2 - spread);   // L_f, Eq. 30
  const double near = f2 * focus_distance_mm / (f2 + spread);  // L_r, Eq. 31
  return far - near;                                           // Eq. 32
}

BlurSpot BlurAt(const FieldSample& sample, const BlurSettings& lens, double focus_distance_mm) {
  BlurSpot blur;
  blur.tangential_px = BlurDiameterMm(lens, sample.tangential_far.lens_distance_mm, focus_distance_mm) / lens.pixel_mm;
  blur.sagittal_px = BlurDiameterMm(lens, sample.sagittal_far.lens_distance_mm, focus_distance_mm) / lens.pixel_mm;
  // Eqs. 36-37: pixels over pixels per degree.
  blur.tangential_deg = std::max(std::abs(blur.tangential_px), 1.0) / sample.delta_h_px;
  blur.sagittal_deg = std::max(std::abs(blur.sagittal_px), 1.0) / sample.delta_w_px;
  blur.area_deg2 = blur.tangential_deg * blur.sagittal_deg;
  return blur;
}

double MeanBlurAreaDeg2(const std::vector<FieldSample>& field, const BlurSettings& lens, double focus_distance_mm) {
  const std::vector<double> weights = SolidAngleWeights(field);
  double sum = 0.0, total = 0.0;
  for (size_t i = 0; i < field.size(); ++i) {
    sum += weights[i] * BlurAt(field[i], lens, focus_distance_mm).area_deg2;
    total += weights[i];
  }
  return sum / total;
}

double BestFocusDistanceMm(const std::vector<FieldSample>& field, const BlurSettings& lens, double* mean_area_deg2) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (const FieldSample& s : field) {
    for (double l : {s.tangential_far.lens_distance_mm, s.sagittal_far.lens_distance_mm}) {
      lo = std::min(lo, l);
      hi = std::max(hi, l);
    }
  }
  lo = std::max(lo, 1.01 * lens.lens_focal_mm);  // a real image needs L0 > f
  auto cost = [&](double l0) { return MeanBlurAreaDeg2(field, lens, l0); };
  const double l0 = MinimizeScanThenBrent(cost, lo, hi, 200);
  if (mean_area_deg2 != nullptr) *mean_area_deg2 = cost(l0);
  return l0;
}

std::vector<AzimuthSample> ExactAzimuthCurve(const Sensor& sensor, double azimuth_rad, int samples) {
  std::vector<AzimuthSample> curve;
  std::visit(
      [&](const auto& model) {
        const Eigen::Matrix3d rotation = model.pose.CameraFromMirrorRotation();
        const Eigen::Vector3d translation = model.pose.CameraFromMirrorTranslation();
        auto pixel_of = [&](double x, Vec2<double>* pixel) {
          const Eigen::Vector3d in_mirror(x * std::cos(azimuth_rad), x * std::sin(azimuth_rad),
                                          model.mirror.EvaluateSag(x * x).z);
          const bool in_front = model.lens.ProjectToPixel(rotation * in_mirror + translation, pixel);
          if (!in_front) pixel->setConstant(NAN);  // the lens writes the pixel either way
          return in_front;
        };
        Vec2<double> vertex_pixel(NAN, NAN);
        pixel_of(0.0, &vertex_pixel);
        for (int i = 1; i <= samples; ++i) {
          const double x = model.rim_radius_mm * i / samples;
          Vec2<double> pixel(NAN, NAN);
          Eigen::Vector3d origin, direction;
          if (!pixel_of(x, &pixel) || sensor.Unproject(pixel, &origin, &direction) != ProjectionStatus::kOk) continue;
          const double down = -(rotation.transpose() * direction).z();
          curve.push_back({x, std::acos(std::clamp(down, -1.0, 1.0)), (pixel - vertex_pixel).norm()});
        }
      },
      sensor.model());
  return curve;
}

std::string RimOutsideImage(const Sensor& sensor) {
  return std::visit(
      [&](const auto& model) -> std::string {
        const Eigen::Matrix3d rotation = model.pose.CameraFromMirrorRotation();
        const Eigen::Vector3d translation = model.pose.CameraFromMirrorTranslation();
        const double rim = model.rim_radius_mm;
        for (int k = 0; k < 72; ++k) {
          const double azimuth = 2.0 * M_PI * k / 72;
          const Eigen::Vector3d rim_point(rim * std::cos(azimuth), rim * std::sin(azimuth),
                                          model.mirror.EvaluateSag(rim * rim).z);
          Vec2<double> pixel(NAN, NAN);
          // A rim exactly on the image border (the seed's 2N = 1000 design) is inside: allow
          // the rounding of the projection.
          constexpr double kTolerancePx = 1e-6;
          if (!model.lens.ProjectToPixel(rotation * rim_point + translation, &pixel)) pixel.setConstant(NAN);
          if (!(pixel.x() >= -0.5 - kTolerancePx && pixel.x() <= model.image_width_px - 0.5 + kTolerancePx &&
                pixel.y() >= -0.5 - kTolerancePx && pixel.y() <= model.image_height_px - 0.5 + kTolerancePx)) {
            char text[160];
            std::snprintf(text, sizeof text, "the mirror rim images outside the %d x %d image (at azimuth %d deg: %.1f, %.1f px)",
                          model.image_width_px, model.image_height_px, 5 * k, pixel.x(), pixel.y());
            return text;
          }
        }
        return {};
      },
      sensor.model());
}

double MeanSolidAnglePerPixelDeg2(const std::vector<FieldSample>& field) {
  const FieldSample& rim = field.back();
  const double coverage_deg2 = 2.0 * M_PI * (1.0 - std::cos(rim.ray.omega_rad)) * kDegPerRad * kDegPerRad;
  return coverage_deg2 / (M_PI * rim.h_px * rim.h_px);
}

}  // namespace omnical
