#include "calib/projection_diff.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <variant>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/predicted_error.h"
#include "model/input_error.h"
#include "model/object_distance.h"

namespace omnical {
namespace {

// Pixels of `points` moved by (angle-axis, translation), through `sensor`; false if any
// does not project (a step that pushes a field point off the mirror is not taken).
bool MovedPixels(const Sensor& sensor, const Eigen::Matrix3Xd& points, const double* angle_axis, const double* translation,
                 Eigen::Matrix2Xd* pixels, std::vector<ProjectionStatus>* statuses) {
  Eigen::Matrix3d rotation;
  ceres::AngleAxisToRotationMatrix(angle_axis, ceres::ColumnMajorAdapter3x3(rotation.data()));
  const Eigen::Matrix3Xd moved = (rotation * points).colwise() + Eigen::Vector3d(translation[0], translation[1], translation[2]);
  sensor.ProjectBatch(moved, pixels, statuses);
  return std::all_of(statuses->begin(), statuses->end(), [](ProjectionStatus s) { return s == ProjectionStatus::kOk; });
}
bool MovedPixels(const Sensor& sensor, const Eigen::Matrix3Xd& points, const double* angle_axis, const double* translation,
                 Eigen::Matrix2Xd* pixels) {
  std::vector<ProjectionStatus> statuses;
  return MovedPixels(sensor, points, angle_axis, translation, pixels, &statuses);
}

// The sensor with no camera body: the alignment needs where a point is seen, not whether
// the body's reflection covers it.
Sensor WithoutCameraBody(const Sensor& sensor) {
  return std::visit(
      [](auto model) {
        model.camera_body_radius_mm = 0.0;
        return Sensor(model);
      },
      sensor.model());
}

// All field points at once: one batch projection per evaluation, the 2N x 6 Jacobian by
// finite differences, central where a point projects on both sides of the step (the
// batch path has no Jets; six parameters make that cheap).
class AlignmentCost : public ceres::CostFunction {
 public:
  AlignmentCost(const Sensor& other, Eigen::Matrix3Xd points, Eigen::Matrix2Xd targets_px)
      : other_(other), points_(std::move(points)), targets_px_(std::move(targets_px)) {
    set_num_residuals(static_cast<int>(2 * points_.cols()));
    mutable_parameter_block_sizes()->push_back(3);
    mutable_parameter_block_sizes()->push_back(3);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    Eigen::Matrix2Xd pixels;
    if (!MovedPixels(other_, points_, parameters[0], parameters[1], &pixels)) return false;
    Eigen::Map<Eigen::Matrix2Xd>(residuals, 2, points_.cols()) = pixels - targets_px_;
    if (!jacobians) return true;
    // Steps: 1e-6 rad and 1e-4 mm move a pixel by ~1e-3 px, far above the solvers'
    // 1e-10 px and small enough to stay linear.
    constexpr double kStep[2] = {1e-6, 1e-4};
    for (int block = 0; block < 2; ++block) {
      if (!jacobians[block]) continue;
      for (int k = 0; k < 3; ++k) {
        double plus[2][3], minus[2][3];
        for (int b = 0; b < 2; ++b)
          for (int i = 0; i < 3; ++i) plus[b][i] = minus[b][i] = parameters[b][i];
        plus[block][k] += kStep[block];
        minus[block][k] -= kStep[block];
        // Per point: central where both sides project, one-sided where one does, zero
        // where neither (that point then steers no step). Failing the whole evaluation
        // instead would end the solve at the first accepted point with a field point
        // within a step of the rim, and leave the two calibrations unaligned.
        Eigen::Matrix2Xd up, down;
        std::vector<ProjectionStatus> up_status, down_status;
        MovedPixels(other_, points_, plus[0], plus[1], &up, &up_status);
        MovedPixels(other_, points_, minus[0], minus[1], &down, &down_status);
        for (Eigen::Index p = 0; p < points_.cols(); ++p) {
          const bool has_up = up_status[p] == ProjectionStatus::kOk, has_down = down_status[p] == ProjectionStatus::kOk;
          Eigen::Vector2d column = Eigen::Vector2d::Zero();
          if (has_up && has_down) column = (up.col(p) - down.col(p)) / (2.0 * kStep[block]);
          else if (has_up) column = (up.col(p) - pixels.col(p)) / kStep[block];
          else if (has_down) column = (pixels.col(p) - down.col(p)) / kStep[block];
          jacobians[block][(2 * p) * 3 + k] = column.x();
          jacobians[block][(2 * p + 1) * 3 + k] = column.y();
        }
      }
    }
    return true;
  }

 private:
  const Sensor& other_;
  Eigen::Matrix3Xd points_;
  Eigen::Matrix2Xd targets_px_;
};

// The reference's points distance_mm along the pixels' rays (columns of *points) and the
// pixels (*kept_pixels) where both sensors project them; returns their indices.
std::vector<size_t> PointsBothProject(const Sensor& reference, const Sensor& other,
                                      const std::vector<Eigen::Vector2d>& pixels, double distance_mm,
                                      Eigen::Matrix3Xd* points, Eigen::Matrix2Xd* kept_pixels) {
  const Eigen::Matrix3Xd all = PointsAlongRays(reference, pixels, distance_mm);  // NaN where unprojectable
  Eigen::Matrix2Xd through_other;
  std::vector<ProjectionStatus> projected;
  other.ProjectBatch(all, &through_other, &projected);
  std::vector<size_t> kept;
  for (size_t k = 0; k < pixels.size(); ++k)
    if (projected[k] == ProjectionStatus::kOk && all.col(k).allFinite()) kept.push_back(k);
  points->resize(3, kept.size());
  kept_pixels->resize(2, kept.size());
  for (size_t i = 0; i < kept.size(); ++i) points->col(i) = all.col(kept[i]), kept_pixels->col(i) = pixels[kept[i]];
  return kept;
}

}  // namespace

std::vector<Eigen::Vector2d> ComparisonField(const Sensor& reference, const DetectionSet* detections, double step_px) {
  // As the CLI's --step-px: finer grids only cost time (0.01 px ran for minutes).
  if (!(step_px >= 1.0 && step_px <= 1000.0)) throw InputError("step_px: must be 1 to 1000");
  bool any_corner = false;
  if (detections)
    for (const ImageDetections& image : detections->images) any_corner |= !image.corners.empty();
  ObservedField field;
  if (any_corner) {
    field = FieldOfCorners(reference, *detections);
  } else {
    field = FieldOfCorners(reference, DetectionSet());  // the centre; radii set below
    field.inner_radius_px = 0.0;
    field.outer_radius_px = HUGE_VAL;
  }
  return FieldPixels(reference, field, step_px);
}

ProjectionDiff CompareProjections(const Sensor& reference, const Sensor& other, const std::vector<Eigen::Vector2d>& pixels,
                                  double distance_mm, bool align, double align_at_mm) {
  if (const std::string why = ObjectDistanceProblem(distance_mm); !why.empty()) throw InputError("distance_mm: " + why);
  if (!align && !std::isnan(align_at_mm)) throw InputError("align_at_mm: given without the alignment (align off)");
  const double fit_at_mm = std::isnan(align_at_mm) ? distance_mm : align_at_mm;
  if (const std::string why = ObjectDistanceProblem(fit_at_mm); align && !why.empty())
    throw InputError("align_at_mm: " + why);
  ProjectionDiff diff;
  diff.distance_mm = distance_mm;
  diff.pixels = pixels;
  diff.difference_px.assign(pixels.size(), Eigen::Vector2d::Constant(NAN));
  Eigen::Matrix3Xd kept_points;
  Eigen::Matrix2Xd kept_pixels;
  const std::vector<size_t> kept = PointsBothProject(reference, other, pixels, distance_mm, &kept_points, &kept_pixels);
  if (kept.size() < 6)
    throw InputError("field: only " + std::to_string(kept.size()) +
                     " field pixels project through both calibrations (need >= 6): are they of the same camera?");

  double angle_axis[3] = {0.0, 0.0, 0.0}, translation[3] = {0.0, 0.0, 0.0};
  // The alignment's steps (and its central differences) move points at the rim a little
  // past it: through a 15 % wider rim they still project (as the bundle fit's cost does).
  // Nor does the camera body hide any (a point moving into its shadow would stop a step).
  const Sensor wide = WithoutCameraBody(SensorWithWiderRim(other, 1.15));
  Eigen::Matrix2Xd before;
  MovedPixels(wide, kept_points, angle_axis, translation, &before);
  if (align) {
    Eigen::Matrix3Xd fit_points = kept_points;
    Eigen::Matrix2Xd fit_pixels = kept_pixels;
    if (fit_at_mm != distance_mm &&
        PointsBothProject(reference, other, pixels, fit_at_mm, &fit_points, &fit_pixels).size() < 6)
      throw InputError("align_at_mm: only " + std::to_string(fit_points.cols()) +
                       " field pixels project through both calibrations at that distance (need >= 6)");
    ceres::Problem problem;
    problem.AddResidualBlock(new AlignmentCost(wide, fit_points, fit_pixels), nullptr, angle_axis, translation);
    // At infinity a translation moves no point: only the rotation is determined.
    if (fit_at_mm >= kInfinityMm) problem.SetParameterBlockConstant(translation);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 100;
    options.function_tolerance = 1e-14;
    options.parameter_tolerance = 1e-14;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    diff.aligned = summary.IsSolutionUsable();
    if (diff.aligned) diff.aligned_at_mm = fit_at_mm;
    else angle_axis[0] = angle_axis[1] = angle_axis[2] = translation[0] = translation[1] = translation[2] = 0.0;
  }
  // Fitted at the compared distance, every moved point projects (the solver takes no step
  // where one does not); fitted elsewhere, a point moved past the rim is not compared.
  Eigen::Matrix2Xd after;
  std::vector<ProjectionStatus> after_status;
  MovedPixels(wide, kept_points, angle_axis, translation, &after, &after_status);
  const Eigen::Vector3d rotation_vector(angle_axis[0], angle_axis[1], angle_axis[2]);
  diff.rotation_deg = rotation_vector.norm() * 180.0 / M_PI;
  diff.rotation = rotation_vector.norm() > 0.0 ? Eigen::Quaterniond(Eigen::AngleAxisd(rotation_vector.norm(), rotation_vector.normalized()))
                                               : Eigen::Quaterniond::Identity();
  diff.translation_mm = Eigen::Vector3d(translation[0], translation[1], translation[2]);
  std::vector<double> lengths;
  double square = 0.0, unaligned_square = 0.0;
  for (size_t i = 0; i < kept.size(); ++i) {
    if (after_status[i] != ProjectionStatus::kOk) {
      ++diff.moved_off_mirror;
      continue;
    }
    const Eigen::Vector2d d = after.col(i) - kept_pixels.col(i);
    diff.difference_px[kept[i]] = d;
    lengths.push_back(d.norm());
    square += d.squaredNorm();
    unaligned_square += (before.col(i) - kept_pixels.col(i)).squaredNorm();
  }
  diff.compared = static_cast<int>(lengths.size());
  if (diff.compared < 6)
    throw InputError("align_at_mm: the rigid motion fitted there moves all but " + std::to_string(diff.compared) +
                     " field points off the other calibration's mirror (need >= 6 compared)");
  // Before and after over the same pixels: those compared.
  diff.rms_px = std::sqrt(square / diff.compared);
  diff.unaligned_rms_px = std::sqrt(unaligned_square / diff.compared);
  MedianAndMax(lengths, &diff.median_px, &diff.max_px);
  return diff;
}

}  // namespace omnical
