#include "calib/predicted_error.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace omnical {
namespace {

double ParameterValue(const Sensor& sensor, const std::string& name, double fallback) {
  for (const ParameterEstimate& p : SensorParameters(sensor))
    if (p.name == name) return p.value;
  return fallback;
}

Eigen::Matrix2Xd Projected(const Sensor& sensor, const Eigen::Matrix3Xd& points) {
  Eigen::Matrix2Xd pixels;
  std::vector<ProjectionStatus> statuses;
  sensor.ProjectBatch(points, &pixels, &statuses);
  for (size_t k = 0; k < statuses.size(); ++k)
    if (statuses[k] != ProjectionStatus::kOk) pixels.col(k).setConstant(NAN);
  return pixels;
}

// sqrt(trace(J C J^T)) for one pixel's 2 x parameters Jacobian J; NaN where the pixel does
// not project through a step.
double StdOf(const Eigen::MatrixXd& jacobian, const Eigen::MatrixXd& covariance) {
  if (!jacobian.allFinite()) return NAN;
  return std::sqrt(std::max(0.0, (jacobian * covariance * jacobian.transpose()).trace()));
}

// The pixel motion of the points under a small rigid motion of the sensor's frame, one
// column per generator (rotation about each axis; at a finite distance also translation
// along each), rows x0, y0, x1, y1, ... A calibration chooses its frame as freely as the
// poses allow (a pinhole's principal point with the mirror's tilt and decenter nearly
// turns the camera), so what these explain is no error: omnical diff and the
// cross-validation align it away, and so does the prediction.
Eigen::MatrixXd RigidMotionFields(const Sensor& sensor, const Eigen::Matrix3Xd& points, bool with_translation) {
  // 1e-6 rad and 1e-4 mm: as the alignment's steps (calib/projection_diff.cc).
  constexpr double kTurnRad = 1e-6, kShiftMm = 1e-4;
  const int generators = with_translation ? 6 : 3;
  Eigen::MatrixXd fields(2 * points.cols(), generators);
  for (int g = 0; g < generators; ++g) {
    const int axis = g % 3;
    const double step = g < 3 ? kTurnRad : kShiftMm;
    Eigen::Matrix3Xd plus = points, minus = points;
    if (g < 3) {
      const Eigen::Matrix3d turn = Eigen::AngleAxisd(step, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
      plus = turn * points;
      minus = turn.transpose() * points;
    } else {
      plus.row(axis).array() += step;
      minus.row(axis).array() -= step;
    }
    const Eigen::Matrix2Xd moved = (Projected(sensor, plus) - Projected(sensor, minus)) / (2.0 * step);
    fields.col(g) = Eigen::Map<const Eigen::VectorXd>(moved.data(), moved.size());
  }
  return fields;
}

// The rigid motion (generators x parameters) that best explains each parameter's pixel
// motion, least squares over the pixels where both are finite; false where too few are.
bool FitRigidMotion(const Eigen::MatrixXd& rigid, const Eigen::MatrixXd& derivative, Eigen::MatrixXd* motion) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index r = 0; r + 1 < rigid.rows(); r += 2)
    if (derivative.middleRows(r, 2).allFinite() && rigid.middleRows(r, 2).allFinite())
      rows.insert(rows.end(), {r, r + 1});
  if (rows.size() <= 2 * static_cast<size_t>(rigid.cols())) return false;
  Eigen::MatrixXd kept_rigid(rows.size(), rigid.cols()), kept_derivative(rows.size(), derivative.cols());
  for (size_t r = 0; r < rows.size(); ++r) {
    kept_rigid.row(r) = rigid.row(rows[r]);
    kept_derivative.row(r) = derivative.row(rows[r]);
  }
  // Turns in rad and shifts in mm move pixels on other scales: solved on unit columns.
  const Eigen::VectorXd scale = kept_rigid.colwise().norm().transpose();
  const Eigen::MatrixXd unit = kept_rigid * scale.cwiseInverse().asDiagonal();
  *motion = scale.cwiseInverse().asDiagonal() * unit.colPivHouseholderQr().solve(kept_derivative);
  return true;
}

}  // namespace

Eigen::Matrix3Xd PointsAlongRays(const Sensor& sensor, const std::vector<Eigen::Vector2d>& pixels, double distance_mm) {
  Eigen::Matrix2Xd grid(2, pixels.size());
  for (size_t k = 0; k < pixels.size(); ++k) grid.col(k) = pixels[k];
  Eigen::Matrix3Xd origins, directions;
  std::vector<ProjectionStatus> statuses;
  sensor.UnprojectBatch(grid, &origins, &directions, &statuses);
  Eigen::Matrix3Xd points(3, pixels.size());
  for (size_t k = 0; k < pixels.size(); ++k)
    points.col(k) = statuses[k] == ProjectionStatus::kOk
                        ? Eigen::Vector3d(origins.col(k) + distance_mm * directions.col(k))
                        : Eigen::Vector3d::Constant(NAN);
  return points;
}

void MedianAndMax(std::vector<double> values, double* median, double* max) {
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }), values.end());
  if (values.empty()) {
    *median = *max = NAN;
    return;
  }
  *max = *std::max_element(values.begin(), values.end());
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  *median = values[values.size() / 2];
}

double MedianCornerDistanceMm(const Sensor& sensor, const CalibrationTarget& target, const DetectionSet& detections,
                              const FitResult& fit) {
  std::map<int, Eigen::Vector3d> points;
  for (const TargetCorner& c : target.corners()) points[c.id] = c.point_in_target;
  std::vector<double> distances;
  for (size_t v = 0; v < detections.images.size() && v < fit.poses.size(); ++v) {
    if (v < fit.view_left_out.size() && !fit.view_left_out[v].empty()) continue;
    for (const CornerObservation& c : detections.images[v].corners) {
      const auto point = points.find(c.id);
      if (point == points.end()) continue;
      const Eigen::Vector3d in_camera =
          fit.poses[v].camera_from_target_rotation * point->second + fit.poses[v].camera_from_target_translation_mm;
      Eigen::Vector3d mirror_point;
      if (std::visit([&](const auto& m) { return m.ReflectionPoint(in_camera, &mirror_point, &sensor.cache()); },
                     sensor.model()) == ProjectionStatus::kOk)
        distances.push_back((in_camera - mirror_point).norm());
    }
  }
  double median = NAN, farthest = NAN;
  MedianAndMax(distances, &median, &farthest);
  return median;
}

ObservedField FieldOfCorners(const Sensor& sensor, const DetectionSet& detections) {
  ObservedField field;
  field.centre_px = Eigen::Vector2d(ParameterValue(sensor, "cx_px", 0.5 * (sensor.image_width_px() - 1)),
                                    ParameterValue(sensor, "cy_px", 0.5 * (sensor.image_height_px() - 1)));
  field.inner_radius_px = HUGE_VAL;
  for (const ImageDetections& image : detections.images)
    for (const CornerObservation& c : image.corners) {
      const double r = (c.pixel - field.centre_px).norm();
      field.inner_radius_px = std::min(field.inner_radius_px, r);
      field.outer_radius_px = std::max(field.outer_radius_px, r);
    }
  if (!std::isfinite(field.inner_radius_px)) field.inner_radius_px = 0.0;
  return field;
}

std::vector<Eigen::Vector2d> FieldPixels(const Sensor& sensor, const ObservedField& field, double step_px) {
  std::vector<Eigen::Vector2d> pixels;
  for (double v = 0.5 * step_px; v < sensor.image_height_px(); v += step_px)
    for (double u = 0.5 * step_px; u < sensor.image_width_px(); u += step_px) {
      const Eigen::Vector2d pixel(u, v);
      const double r = (pixel - field.centre_px).norm();
      Eigen::Vector3d origin, direction;
      if (r >= field.inner_radius_px && r <= field.outer_radius_px &&
          sensor.Unproject(pixel, &origin, &direction) == ProjectionStatus::kOk)
        pixels.push_back(pixel);
    }
  return pixels;
}

std::vector<PredictedError> PredictProjectionError(const Sensor& sensor, const FitResult& fit,
                                                   const std::vector<Eigen::Vector2d>& pixels,
                                                   const std::vector<double>& distances_mm, double align_at_mm) {
  if (!fit.covariance_ok || fit.covariance.rows() != static_cast<int>(fit.covariance_names.size()))
    throw std::invalid_argument("PredictProjectionError: the fit has no covariance");
  // 5 % wider: a parameter step must not push the outermost field pixels' reflections
  // past the rim, where they would drop out exactly where the error is largest.
  const Sensor wide = SensorWithWiderRim(sensor, 1.05);
  const std::vector<ParameterEstimate> named = SensorParameters(sensor);
  std::vector<double> values;
  for (const ParameterEstimate& p : named) values.push_back(p.value);
  // Index of each covariance row among the sensor's parameters.
  std::vector<size_t> index;
  for (const std::string& name : fit.covariance_names) {
    const auto found = std::find_if(named.begin(), named.end(), [&](const ParameterEstimate& p) { return p.name == name; });
    if (found == named.end()) throw std::invalid_argument("PredictProjectionError: unknown parameter " + name);
    index.push_back(static_cast<size_t>(found - named.begin()));
  }
  const int count = static_cast<int>(index.size());
  // d pixel / d parameter at the points, by central differences, a hundredth of a std
  // each way. A tenth reached into the projection's curvature where a std is large (a
  // near-sphere's tilt, 35 deg): worst 0.136 px at 338 mm against 0.089 with a hundredth
  // or a thousandth (those agree to 3 digits), and 27 field pixels stepped past the rim.
  // The solvers' 1e-10 px stays far below the ~1e-4 px differences.
  const auto parameter_fields = [&](const Eigen::Matrix3Xd& points) {
    Eigen::MatrixXd derivative(2 * points.cols(), count);  // rows x0, y0, x1, y1, ...
    for (int k = 0; k < count; ++k) {
      const double std_k = std::sqrt(std::max(0.0, fit.covariance(k, k)));
      const double step = std::max(0.01 * std_k, 1e-9 * (1.0 + std::abs(values[index[k]])));
      std::vector<double> plus = values, minus = values;
      plus[index[k]] += step;
      minus[index[k]] -= step;
      const Eigen::Matrix2Xd moved =
          (Projected(SensorWithParameters(wide, plus), points) - Projected(SensorWithParameters(wide, minus), points)) /
          (2.0 * step);
      derivative.col(k) = Eigen::Map<const Eigen::VectorXd>(moved.data(), moved.size());
    }
    return derivative;
  };
  // Each parameter's pixel motion and the rigid generators' at one distance.
  struct Fields {
    Eigen::MatrixXd derivative, rigid;
  };
  const auto fields_at = [&](double distance_mm, bool with_translation) {
    const Eigen::Matrix3Xd points = PointsAlongRays(sensor, pixels, distance_mm);
    return Fields{parameter_fields(points), RigidMotionFields(wide, points, with_translation)};
  };
  // One rigid motion per parameter direction, fitted at align_at_mm and applied at every
  // distance (calib/projection_diff.h): its coefficients on the rigid generators. Where
  // too few field pixels project there, each distance is aligned on its own.
  bool align_once = !std::isnan(align_at_mm);
  Eigen::MatrixXd motion_per_parameter;
  Fields at_alignment;
  if (align_once) {
    at_alignment = fields_at(align_at_mm, align_at_mm < kInfinityMm);
    align_once = FitRigidMotion(at_alignment.rigid, at_alignment.derivative, &motion_per_parameter);
  }
  std::vector<PredictedError> maps;
  for (double distance_mm : distances_mm) {
    // At infinity a translation moves nothing: rotation only, unless fitted elsewhere.
    const bool with_translation = align_once ? align_at_mm < kInfinityMm : distance_mm < kInfinityMm;
    // calibrate's first default distance is the alignment's own: its fields are taken.
    Fields here = align_once && distance_mm == align_at_mm ? at_alignment : fields_at(distance_mm, with_translation);
    Eigen::MatrixXd& derivative = here.derivative;
    const Eigen::MatrixXd& rigid = here.rigid;
    PredictedError map;
    map.in_camera_frame_std_px.resize(pixels.size());
    for (size_t p = 0; p < pixels.size(); ++p)
      map.in_camera_frame_std_px[p] = StdOf(derivative.middleRows(2 * p, 2), fit.covariance);
    // Less what a rigid motion of the frame explains, as diff aligns: fitted here by least
    // squares over the pixels that predict, or the one fitted at align_at_mm.
    Eigen::MatrixXd motion = motion_per_parameter;
    // A pixel the alignment could not weigh (its rigid motion does not project, or too few
    // do) has no aligned figure.
    const bool alignable = align_once || FitRigidMotion(rigid, derivative, &motion);
    std::vector<bool> aligned(pixels.size(), false);
    for (size_t p = 0; alignable && p < pixels.size(); ++p) {
      aligned[p] = derivative.middleRows(2 * p, 2).allFinite() && rigid.middleRows(2 * p, 2).allFinite();
      if (aligned[p]) derivative.middleRows(2 * p, 2) -= rigid.middleRows(2 * p, 2) * motion;
    }
    map.distance_mm = distance_mm;
    map.aligned_at_mm = !alignable ? NAN : align_once ? align_at_mm : distance_mm;
    map.aligned_once = alignable && align_once;
    map.pixels = pixels;
    map.std_px.resize(pixels.size());
    for (size_t p = 0; p < pixels.size(); ++p) {
      map.std_px[p] = aligned[p] ? StdOf(derivative.middleRows(2 * p, 2), fit.covariance) : NAN;
      map.unpredicted += !std::isfinite(map.std_px[p]);
    }
    MedianAndMax(map.std_px, &map.median_px, &map.max_px);
    MedianAndMax(map.in_camera_frame_std_px, &map.in_camera_frame_median_px, &map.in_camera_frame_max_px);
    maps.push_back(std::move(map));
  }
  return maps;
}

std::vector<double> ProjectionDisplacement(const Sensor& reference, const Sensor& other,
                                           const std::vector<Eigen::Vector2d>& pixels, double distance_mm) {
  const Eigen::Matrix3Xd points = PointsAlongRays(reference, pixels, distance_mm);
  const Eigen::Matrix2Xd moved = Projected(other, points);
  const Eigen::Matrix2Xd back = Projected(reference, points);
  std::vector<double> displacement(pixels.size());
  for (size_t k = 0; k < pixels.size(); ++k) displacement[k] = (moved.col(k) - back.col(k)).norm();
  return displacement;
}

}  // namespace omnical
