#include "calib/rim_circle.h"

#include <Eigen/QR>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <variant>

#include "calib/bilinear.h"
#include "calib/bundle_fit.h"
#include "model/model_registry.h"

namespace omnical {

namespace {

constexpr int kRays = 720;
constexpr double kInlierPx = 3.0;

double Sample(const cv::Mat& image, double x, double y) { return Bilinear<float>(image, x, y); }

// Per ray from `centre`, the radius in [min_r, max_r] with the largest inside-minus-outside
// step; rays that find no drop of at least 10 grey levels give nothing.
std::vector<Eigen::Vector2d> EdgePoints(const cv::Mat& smooth, const Eigen::Vector2d& centre, double min_r, double max_r,
                                        double inside_px, double outside_px) {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> profile;
  for (int k = 0; k < kRays; ++k) {
    const double angle = 2.0 * M_PI * k / kRays, dx = std::cos(angle), dy = std::sin(angle);
    profile.clear();
    for (double r = std::max(0.0, min_r - inside_px);; r += 1.0) {
      const double v = Sample(smooth, centre.x() + r * dx, centre.y() + r * dy);
      if (!std::isfinite(v) || r > max_r + outside_px) break;
      profile.push_back(v);
    }
    const double first_r = std::max(0.0, min_r - inside_px);
    // Prefix sums for window means.
    std::vector<double> prefix(profile.size() + 1, 0.0);
    for (size_t i = 0; i < profile.size(); ++i) prefix[i + 1] = prefix[i] + profile[i];
    const int inside = std::max(1, static_cast<int>(inside_px)), outside = std::max(2, static_cast<int>(outside_px));
    std::vector<double> steps(profile.size(), 0.0);
    double largest = 10.0;  // a rim drops by 10 grey levels at least
    for (int i = inside; i + 3 <= static_cast<int>(profile.size()); ++i) {
      const double r = first_r + i;
      if (r < min_r || r > max_r) continue;
      const int end = std::min(static_cast<int>(profile.size()), i + outside);
      // Near the frame the outside window is cut short; a rim needs a few dark px at least.
      if (end - i < std::min(outside, 3)) continue;
      steps[i] = (prefix[i] - prefix[i - inside]) / inside - (prefix[end] - prefix[i]) / (end - i);
      largest = std::max(largest, steps[i]);
    }
    // The outermost strong drop (half the ray's largest at least): beyond the rim there is
    // only housing, so a drop further out than an edge of the scene is the rim.
    int chosen = -1;
    for (int i = static_cast<int>(steps.size()) - 1; i >= inside && chosen < 0; --i)
      if (steps[i] >= 0.5 * largest) {
        chosen = i;
        while (chosen > inside && steps[chosen - 1] > steps[chosen]) --chosen;  // climb to the local peak
      }
    if (chosen < 0) continue;
    const double r = first_r + chosen;
    points.emplace_back(centre.x() + r * dx, centre.y() + r * dy);
  }
  return points;
}

// Per ray from `centre`, the steepest descent of the smoothed intensity in [min_r, max_r],
// to sub-pixel (parabola through the peak): local, so unbiased where the frame cuts the
// outside short. For the fine pass, near a circle already found.
std::vector<Eigen::Vector2d> GradientPeaks(const cv::Mat& smooth, const Eigen::Vector2d& centre, double min_r, double max_r) {
  std::vector<Eigen::Vector2d> points;
  constexpr double kStep = 0.25;
  for (int k = 0; k < kRays; ++k) {
    const double angle = 2.0 * M_PI * k / kRays, dx = std::cos(angle), dy = std::sin(angle);
    std::vector<double> drop;  // -dI/dr by central differences
    for (double r = min_r; r <= max_r; r += kStep) {
      const double inner = Sample(smooth, centre.x() + (r - 0.5) * dx, centre.y() + (r - 0.5) * dy);
      const double outer = Sample(smooth, centre.x() + (r + 0.5) * dx, centre.y() + (r + 0.5) * dy);
      if (!std::isfinite(inner) || !std::isfinite(outer)) break;
      drop.push_back(inner - outer);
    }
    if (drop.size() < 3) continue;
    const size_t peak = std::max_element(drop.begin(), drop.end()) - drop.begin();
    if (drop[peak] < 3.0 || peak == 0 || peak + 1 == drop.size()) continue;  // no rim, or at the band's end
    const double a = drop[peak - 1], b = drop[peak], c = drop[peak + 1], curvature = a - 2.0 * b + c;
    const double offset = curvature < 0.0 ? std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5) : 0.0;
    const double r = min_r + (peak + offset) * kStep;
    points.emplace_back(centre.x() + r * dx, centre.y() + r * dy);
  }
  return points;
}

// Algebraic (Kasa) circle through points; false if degenerate.
bool FitCircle(const std::vector<Eigen::Vector2d>& points, Eigen::Vector2d* centre, double* radius) {
  if (points.size() < 3) return false;
  Eigen::MatrixX3d a(points.size(), 3);
  Eigen::VectorXd b(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    a.row(i) << 2.0 * points[i].x(), 2.0 * points[i].y(), 1.0;
    b(i) = points[i].squaredNorm();
  }
  const Eigen::Vector3d x = a.colPivHouseholderQr().solve(b);
  if (!x.allFinite()) return false;
  *centre = x.head<2>();
  const double r2 = x(2) + centre->squaredNorm();
  if (!(r2 > 0.0)) return false;
  *radius = std::sqrt(r2);
  return true;
}

std::optional<RimCircle> RobustCircle(const std::vector<Eigen::Vector2d>& points) {
  if (points.size() < kRays / 4) return std::nullopt;
  std::mt19937 random(12345);  // fixed: the same image gives the same circle
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  std::vector<Eigen::Vector2d> best_inliers;
  for (int iteration = 0; iteration < 400; ++iteration) {
    Eigen::Vector2d centre;
    double radius;
    if (!FitCircle({points[pick(random)], points[pick(random)], points[pick(random)]}, &centre, &radius)) continue;
    std::vector<Eigen::Vector2d> inliers;
    for (const Eigen::Vector2d& p : points)
      if (std::abs((p - centre).norm() - radius) < kInlierPx) inliers.push_back(p);
    if (inliers.size() > best_inliers.size()) best_inliers.swap(inliers);
  }
  RimCircle circle;
  if (best_inliers.size() < kRays / 4 || !FitCircle(best_inliers, &circle.centre_px, &circle.radius_px)) return std::nullopt;
  double sum = 0.0;
  int count = 0;
  for (const Eigen::Vector2d& p : points) {
    const double d = std::abs((p - circle.centre_px).norm() - circle.radius_px);
    if (d < kInlierPx) sum += d * d, ++count;
  }
  if (count < kRays / 4) return std::nullopt;
  circle.inlier_fraction = static_cast<double>(count) / kRays;
  circle.rms_px = std::sqrt(sum / count);
  return circle;
}

}  // namespace

std::optional<RimCircle> DetectRimCircle(const cv::Mat& grey) {
  if (grey.empty() || grey.channels() != 1) return std::nullopt;
  cv::Mat smooth;
  grey.convertTo(smooth, CV_32F);
  cv::GaussianBlur(smooth, smooth, cv::Size(0, 0), 1.5);
  const double half = 0.5 * std::min(grey.cols, grey.rows);
  // Coarse: from the image centre, any radius from a tenth of the frame out to its corners.
  const Eigen::Vector2d image_centre(0.5 * (grey.cols - 1), 0.5 * (grey.rows - 1));
  std::optional<RimCircle> circle =
      RobustCircle(EdgePoints(smooth, image_centre, 0.1 * half, 1.5 * half, 0.03 * half, 0.12 * half));
  if (!circle) return std::nullopt;
  // Fine: from the circle's centre, the steepest descent within a few px of it.
  const double r = circle->radius_px, band = 0.02 * r + 3.0;
  if (auto fine = RobustCircle(GradientPeaks(smooth, circle->centre_px, r - band, r + band))) circle = fine;
  return circle;
}

std::optional<RimCircle> MedianRimCircle(const std::vector<RimCircle>& circles) {
  if (circles.empty()) return std::nullopt;
  auto median = [&](auto value) {
    std::vector<double> values;
    for (const RimCircle& c : circles) values.push_back(value(c));
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
  };
  RimCircle out;
  out.centre_px = Eigen::Vector2d(median([](const RimCircle& c) { return c.centre_px.x(); }),
                                  median([](const RimCircle& c) { return c.centre_px.y(); }));
  out.radius_px = median([](const RimCircle& c) { return c.radius_px; });
  out.inlier_fraction = median([](const RimCircle& c) { return c.inlier_fraction; });
  out.rms_px = median([](const RimCircle& c) { return c.rms_px; });
  return out;
}

std::optional<Sensor> SensorWithImageRim(const Sensor& sensor, const RimCircle& rim, std::string* why,
                                         bool rim_from_corners) {
  constexpr int kCirclePoints = 360;
  // Seen: 1-5.4 % (a first fit's rim 7-12 px off). Near the rim a mirror's image changes
  // little with its radius, so a few px there are several % in mm; 5 % refused the 5.4 %
  // of realistic checkerboard seed 6 and lost 4 rim junctions.
  constexpr double kMaxRimChangeRatio = 0.10;
  // Outwards a conic whose rim is its corners' may grow further: where no board reached the
  // rim the images' circle lies beyond them, and a conic's curvature continues there as the
  // mirror's does (the realistic checkerboard render from the images alone: the even
  // asphere's first fit put the circle 10.06 % out; widened, its 3 rim boards were found and
  // the calibration ended 0.013 px from the true sensor at 300 mm). Free-form terms are
  // extrapolated there, not measured: the polynomial put the same circle 19 % out, and
  // through it the rim boards drove the refit to a 6 px RMS (calib/profile_choice.h). A
  // design's rim is the mirror's: a circle far beyond it is some other ring.
  constexpr double kMaxConicRimGrowthRatio = 0.25;
  const bool free_form = std::visit([](const auto& model) { return HasFreeFormTerms(model.mirror); }, sensor.model());
  const bool conic_growth = rim_from_corners && !free_form;
  const double max_growth = conic_growth ? kMaxConicRimGrowthRatio : kMaxRimChangeRatio;
  // Wide enough that a circle beyond the largest growth allowed still meets the mirror (and
  // is measured, not counted as beyond it).
  const Sensor wide = SensorWithWiderRim(sensor, 1.0 + kMaxConicRimGrowthRatio + 0.05);
  std::vector<double> radii_mm;
  for (int k = 0; k < kCirclePoints; ++k) {
    const double angle = 2.0 * M_PI * k / kCirclePoints;
    const Eigen::Vector2d pixel = rim.centre_px + rim.radius_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    Eigen::Vector3d origin, direction;  // origin: the reflection point
    const ProjectionStatus status = wide.Unproject(pixel, &origin, &direction);
    if (status == ProjectionStatus::kOk)
      radii_mm.push_back(sensor.cache().InMirrorFrame(origin).head<2>().norm());
    else if (status == ProjectionStatus::kOutsideMirror || status == ProjectionStatus::kMissesMirror)
      radii_mm.push_back(HUGE_VAL);  // beyond what `wide` sees: counted, or the median would lean inwards
  }
  char circle[160];
  std::snprintf(circle, sizeof circle, "the images' rim circle (centre %.1f, %.1f px, radius %.1f px)", rim.centre_px.x(),
                rim.centre_px.y(), rim.radius_px);
  if (radii_mm.size() < kCirclePoints / 2) {
    if (why) *why = std::string(circle) + " lies in the image at under half its points";
    return std::nullopt;
  }
  std::nth_element(radii_mm.begin(), radii_mm.begin() + radii_mm.size() / 2, radii_mm.end());
  const double rim_mm = radii_mm[radii_mm.size() / 2];
  const double change = rim_mm / sensor.rim_radius_mm() - 1.0;
  if (!(change >= -kMaxRimChangeRatio && change <= max_growth)) {  // inf too
    if (why) {
      char text[320];
      if (std::isfinite(rim_mm))
        std::snprintf(text, sizeof text,
                      "%s is a mirror radius of %.2f mm through the fit, whose rim is %.2f mm: over %.0f %% %s", circle,
                      rim_mm, sensor.rim_radius_mm(), 100.0 * (change < 0.0 ? kMaxRimChangeRatio : max_growth),
                      change < 0.0         ? "inside it"
                      : conic_growth       ? "beyond it"
                      : rim_from_corners   ? "beyond it (free-form terms only extrapolate there)"
                                           : "beyond the design's rim");
      else
        std::snprintf(text, sizeof text, "%s lies mostly beyond the fit's mirror (rim %.2f mm)", circle, sensor.rim_radius_mm());
      *why = text;
    }
    return std::nullopt;
  }
  return SensorWithWiderRim(sensor, rim_mm / sensor.rim_radius_mm());
}

}  // namespace omnical
