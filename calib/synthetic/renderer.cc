#include "calib/synthetic/renderer.h"

#include "model/parallel_rows.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <random>

namespace omnical {
namespace {

constexpr double kRimShadow = 0.02;   // outside the mirror: the dark rim and housing
constexpr double kCameraBody = 0.07;  // the camera's reflection
constexpr double kBoardBack = 0.6;    // the unprinted back of a board

// Where a ray meets a target plane within its printed extent: distance along the ray
// and the reflectance there (back face: kBoardBack). False if it misses.
bool HitTarget(const PlacedTarget& placed, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
               double* distance, double* reflectance) {
  const Eigen::Vector3d normal = placed.camera_from_target_rotation.col(2);
  const double along = direction.dot(normal);
  if (std::abs(along) < 1e-12) return false;
  double t = (placed.camera_from_target_translation_mm - origin).dot(normal) / along;
  // A bent board: Newton from the flat plane's hit on z - offset(x, y) = 0 along the ray
  // (a few mm of bend over a board's width: converged to 1e-9 mm in 2-3 steps).
  if (!placed.surface.warp.IsZero()) {
    const Eigen::Vector3d o = placed.camera_from_target_rotation.transpose() * (origin - placed.camera_from_target_translation_mm);
    const Eigen::Vector3d d = placed.camera_from_target_rotation.transpose() * direction;
    for (int step = 0; step < 8; ++step) {
      const Eigen::Vector3d p = o + t * d;
      const double f = p.z() - placed.surface.OffsetMm(p.x(), p.y());
      const double slope = d.z() - placed.surface.Slope(p.x(), p.y()).dot(d.head<2>());
      if (std::abs(slope) < 1e-12) return false;
      t -= f / slope;
      if (std::abs(f) < 1e-9) break;
    }
  }
  if (!(t > 0.0)) return false;
  const Eigen::Vector3d in_target =
      placed.camera_from_target_rotation.transpose() * (origin + t * direction - placed.camera_from_target_translation_mm);
  const double value = placed.target->Reflectance(in_target.x(), in_target.y());
  if (value < 0.0) return false;
  *distance = t;
  *reflectance = along < 0.0 ? value : kBoardBack;  // the printed face looks along +z
  return true;
}

double EnvironmentAt(const Environment& env, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  if (env.type == Environment::Type::kGrey) return env.level;
  // A cube room centred on the sensor with checker tiles: the wall the ray meets first.
  double t = HUGE_VAL;
  int axis = 0;
  for (int k = 0; k < 3; ++k) {
    if (direction[k] == 0.0) continue;
    const double tk = ((direction[k] > 0.0 ? env.half_size_mm : -env.half_size_mm) - origin[k]) / direction[k];
    if (tk > 0.0 && tk < t) t = tk, axis = k;
  }
  if (axis != 2 && !env.tiled_walls) return 0.5 * (env.low + env.high);
  const Eigen::Vector3d hit = origin + t * direction;
  const int a = static_cast<int>(std::floor(hit[(axis + 1) % 3] / env.tile_mm));
  const int b = static_cast<int>(std::floor(hit[(axis + 2) % 3] / env.tile_mm));
  return ((a + b) & 1) ? env.high : env.low;
}

}  // namespace

cv::Mat RenderView(const Sensor& sensor, const PixelRayGrid& rays, const SceneView& view,
                   const Environment& environment, const ImageFormation& formation, unsigned view_index, int threads,
                   const std::function<void(long)>& progress) {
  const int width = sensor.image_width_px(), height = sensor.image_height_px();
  const int side = static_cast<int>(std::lround(std::sqrt(formation.samples_per_pixel)));
  cv::Mat radiance(height, width, CV_64F);
  ParallelRows(height, threads, [&](int v) {
    for (int u = 0; u < width; ++u) {
      double sum = 0.0;
      for (int j = 0; j < side; ++j) {
        for (int i = 0; i < side; ++i) {
          const double su = u - 0.5 + (i + 0.5) / side, sv = v - 0.5 + (j + 0.5) / side;
          Eigen::Vector3d origin, direction;
          const ProjectionStatus status = rays.Ray(su, sv, &origin, &direction);
          if (status != ProjectionStatus::kOk) {
            sum += status == ProjectionStatus::kOccludedByCamera ? kCameraBody : kRimShadow;
            continue;
          }
          double nearest = HUGE_VAL, value = EnvironmentAt(environment, origin, direction);
          for (const PlacedTarget& placed : view.targets) {
            double t = 0.0, reflectance = 0.0;
            if (HitTarget(placed, origin, direction, &t, &reflectance) && t < nearest) nearest = t, value = reflectance;
          }
          sum += value;
        }
      }
      radiance.at<double>(v, u) = sum / (side * side);
    }
    if (progress) progress(1);
  });

  // Vignetting around the image of the axis, normalised by the rim's image radius.
  if (formation.vignetting > 0.0) {
    Eigen::Vector2d centre(0.5 * (width - 1), 0.5 * (height - 1));
    Eigen::Vector2d axis_pixel;
    const ProjectionCache& cache = sensor.cache();
    if (sensor.Project(cache.camera_from_mirror_rotation * Eigen::Vector3d(0, 0, -1e6) + cache.camera_from_mirror_translation,
                       &axis_pixel) == ProjectionStatus::kOk)
      centre = axis_pixel;
    const double rim_px = 0.5 * std::min(width, height);
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u) {
        const double r2 = ((u - centre.x()) * (u - centre.x()) + (v - centre.y()) * (v - centre.y())) / (rim_px * rim_px);
        radiance.at<double>(v, u) *= std::max(0.0, 1.0 - formation.vignetting * r2);
      }
  }
  cv::Mat grey = radiance * 255.0;
  if (formation.blur_sigma_px > 0.0) cv::GaussianBlur(grey, grey, cv::Size(0, 0), formation.blur_sigma_px);
  // Colour: a warm white balance (B, G, R gains of an indoor scene under tungsten light,
  // uncorrected), each channel with its own noise, as a Bayer camera's demosaiced output.
  std::vector<cv::Mat> channels;
  if (formation.colour) {
    for (double gain : {0.72, 0.9, 1.0}) channels.push_back(grey * gain);
  } else {
    channels.push_back(grey);
  }
  if (formation.noise_sigma > 0.0) {
    std::mt19937_64 rng(static_cast<uint64_t>(formation.seed) * 1000003ull + view_index);
    std::normal_distribution<double> noise(0.0, formation.noise_sigma);
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u)
        for (cv::Mat& channel : channels) channel.at<double>(v, u) += noise(rng);
  }
  cv::Mat merged, image;
  cv::merge(channels, merged);
  merged.convertTo(image, formation.colour ? CV_8UC3 : CV_8U);  // rounds and saturates
  return image;
}

std::vector<TargetTruth> GroundTruth(const Sensor& sensor, const SceneView& view) {
  std::vector<TargetTruth> truth;
  for (const PlacedTarget& placed : view.targets) {
    TargetTruth target{&placed, {}};
    const Eigen::Vector3d normal = placed.camera_from_target_rotation.col(2);
    for (const TargetCorner& corner : placed.target->corners()) {
      CornerTruth c;
      c.id = corner.id;
      c.point_in_target_mm = corner.point_in_target +
                             Eigen::Vector3d(0.0, 0.0, placed.surface.OffsetMm(corner.point_in_target.x(), corner.point_in_target.y()));
      c.point_in_camera_mm = placed.camera_from_target_rotation * c.point_in_target_mm + placed.camera_from_target_translation_mm;
      c.pixel = Eigen::Vector2d::Constant(NAN);
      Eigen::Vector3d mirror_point;
      c.status = std::visit(
          [&](const auto& m) { return m.ReflectionPoint(c.point_in_camera_mm, &mirror_point, &sensor.cache()); },
          sensor.model());
      if (c.status == ProjectionStatus::kOk) c.status = sensor.Project(c.point_in_camera_mm, &c.pixel);
      c.visible = c.status == ProjectionStatus::kOk && (mirror_point - c.point_in_camera_mm).dot(normal) > 0.0;
      if (c.visible) {
        // Hidden when another target lies between the corner and the mirror.
        const Eigen::Vector3d toward_mirror = mirror_point - c.point_in_camera_mm;
        const double length = toward_mirror.norm();
        for (const PlacedTarget& other : view.targets) {
          if (&other == &placed) continue;
          double t = 0.0, reflectance = 0.0;
          if (HitTarget(other, c.point_in_camera_mm, toward_mirror / length, &t, &reflectance) && t < length) {
            c.visible = false;
            break;
          }
        }
      }
      target.corners.push_back(c);
    }
    truth.push_back(std::move(target));
  }
  return truth;
}

}  // namespace omnical
