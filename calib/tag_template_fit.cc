#include "calib/tag_template_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

#include "calib/bundle_fit.h"
#include "model/scalar.h"

namespace omnical {

namespace {

// The fitted pixels: their grey values, and the rays of a grid of pixels around the tag;
// per fitted pixel the indices of the rays of the 3 x 3 pixels around it (pixel -> board
// to second order), and the ink rectangles within its reach (indices from
// rectangle_begin[i] to rectangle_begin[i + 1]).
struct FitPixels {
  std::vector<Eigen::Vector3d> origins, directions;  // camera frame, per grid pixel
  std::vector<double> grey;
  std::vector<std::array<int, 9>> rays;  // the 3 x 3 around the pixel, row by row
  std::vector<int> rectangle_begin, rectangles;
};

// The share of the blur's variance left to the separable Gaussian around each quadrature
// node (the rest spreads the nodes): the more, the less of the bend is modelled; the less,
// the farther apart the nodes sit in units of that Gaussian, and the sum turns lumpy. On
// noise-free renders of the rim1 board and a mid-field one (blur 0.8 px): 0.35 put the
// corners 0.11 and 0.02 px from the truth, 0.5 0.17 and 0.03; a fixed residual sigma of
// 0.15 / 0.3 / 0.45 px 0.22 / 0.14 / 0.11 at the rim.
constexpr double kResidualBlurFraction = 0.35;
constexpr size_t kMaxPixels = 1500;
constexpr int kRimClearancePx = 3;

// Parameters: the tag's board pose, camera_from_board (angle-axis, 3; translation mm, 3);
// log sigma_px; ink and paper levels.
constexpr int kNumParams = 9;

class TagResidual {
 public:
  // The residual of fitted pixel `i`.
  TagResidual(const FitPixels& pixels, const std::vector<Eigen::Vector4d>& rectangles, size_t i)
      : pixels_(pixels), rectangles_(rectangles), i_(i) {}

  template <typename T>
  bool operator()(const T* p, T* residuals) const {
    using std::exp;
    using std::sqrt;
    using std::erfc;
    // board_from_camera: the transpose of the pose's rotation.
    T rotation[9];  // row-major camera_from_board
    ceres::AngleAxisToRotationMatrix(p, ceres::RowMajorAdapter3x3(rotation));
    const Eigen::Matrix<T, 3, 1> normal(rotation[2], rotation[5], rotation[8]);
    const Eigen::Matrix<T, 3, 1> centre(p[3], p[4], p[5]);
    // Where a ray meets the board's plane, in board mm (x, y); false when it runs along it
    // or meets it behind its origin (Ceres then refuses the step).
    auto board = [&](int ray, T* x, T* y) {
      const Eigen::Vector3d& o = pixels_.origins[ray];
      const Eigen::Vector3d& d = pixels_.directions[ray];
      const T along = normal.x() * d.x() + normal.y() * d.y() + normal.z() * d.z();
      if (!(std::abs(ScalarPart(along)) > 1e-9)) return false;
      const T t = (normal.x() * (centre.x() - o.x()) + normal.y() * (centre.y() - o.y()) + normal.z() * (centre.z() - o.z())) / along;
      if (!(ScalarPart(t) > 0.0)) return false;
      const T px = o.x() + t * d.x() - centre.x(), py = o.y() + t * d.y() - centre.y(), pz = o.z() + t * d.z() - centre.z();
      *x = rotation[0] * px + rotation[3] * py + rotation[6] * pz;
      *y = rotation[1] * px + rotation[4] * py + rotation[7] * pz;
      return true;
    };
    auto cdf = [](const T& z) { return T(0.5) * erfc(-z * T(M_SQRT1_2)); };
    const T sigma_px = exp(p[6]), ink = p[7], paper = p[8];
    // The pixel's box (variance 1/12 px^2 per axis) and the blur, as one Gaussian in the
    // omni image, split in two: a part integrated by 3 x 3 Gauss-Hermite nodes, each
    // carried to the board through the quadratic of pixel -> board over the 3 x 3 rays
    // around the pixel (there the map shears and bends over the blur's width: near the rim
    // a single Gaussian per board axis put the corners 0.36 px off on a noise-free
    // render), and the rest (kResidualBlurFraction of the variance) as one Gaussian per
    // board axis around each node, which blurs the ink's rectangles separably.
    const T variance_px2 = sigma_px * sigma_px + T(1.0 / 12.0);
    const T residual_variance = T(kResidualBlurFraction) * variance_px2;
    const T node_px = sqrt(T(3.0) * (variance_px2 - residual_variance));
    constexpr double kNodeWeights[3] = {1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0};
    const size_t i = i_;
    const std::array<int, 9>& ray = pixels_.rays[i];
    T bx[9], by[9];
    for (int j = 0; j < 9; ++j)
      if (!board(ray[j], &bx[j], &by[j])) return false;
    // pixel -> board to second order: board mm per omni px along u (a, c) and v (b, d),
    // and the second derivatives.
    const T a = T(0.5) * (bx[5] - bx[3]), c = T(0.5) * (by[5] - by[3]), b = T(0.5) * (bx[7] - bx[1]),
            d = T(0.5) * (by[7] - by[1]);
    const T uu_x = bx[5] + bx[3] - T(2.0) * bx[4], uu_y = by[5] + by[3] - T(2.0) * by[4];
    const T vv_x = bx[7] + bx[1] - T(2.0) * bx[4], vv_y = by[7] + by[1] - T(2.0) * by[4];
    const T uv_x = T(0.25) * (bx[8] - bx[6] - bx[2] + bx[0]), uv_y = T(0.25) * (by[8] - by[6] - by[2] + by[0]);
    const T sx = sqrt(residual_variance * (a * a + b * b)), sy = sqrt(residual_variance * (c * c + d * d));
    // Ink within 6 sigma on both axes (farther it adds under 1e-9): tested on the scalar
    // parts before any erfc of a Jet.
    const double reach_x = 6.0 * ScalarPart(sx), reach_y = 6.0 * ScalarPart(sy);
    T coverage(0.0);
    for (int ju = 0; ju < 3; ++ju)
      for (int jv = 0; jv < 3; ++jv) {
        const T du = T(ju - 1) * node_px, dv = T(jv - 1) * node_px;
        const T x = bx[4] + a * du + b * dv + T(0.5) * (uu_x * du * du + vv_x * dv * dv) + uv_x * du * dv;
        const T y = by[4] + c * du + d * dv + T(0.5) * (uu_y * du * du + vv_y * dv * dv) + uv_y * du * dv;
        const double x0 = ScalarPart(x), y0 = ScalarPart(y);
        T ink_here(0.0);
        for (int k = pixels_.rectangle_begin[i]; k < pixels_.rectangle_begin[i + 1]; ++k) {
          const Eigen::Vector4d& r = rectangles_[pixels_.rectangles[k]];
          if (x0 < r(0) - reach_x || x0 > r(0) + r(2) + reach_x || y0 < r(1) - reach_y || y0 > r(1) + r(3) + reach_y)
            continue;
          ink_here += (cdf((T(r(0) + r(2)) - x) / sx) - cdf((T(r(0)) - x) / sx)) *
                      (cdf((T(r(1) + r(3)) - y) / sy) - cdf((T(r(1)) - y) / sy));
        }
        coverage += T(kNodeWeights[ju] * kNodeWeights[jv]) * ink_here;
      }
    if (coverage > T(1.0)) coverage = T(1.0);
    residuals[0] = paper + (ink - paper) * coverage - T(pixels_.grey[i]);
    return true;
  }

 private:
  const FitPixels& pixels_;
  const std::vector<Eigen::Vector4d>& rectangles_;
  size_t i_;
};

}  // namespace

bool FitTagTemplate(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, int tag,
                    const std::array<Eigen::Vector2d, 4>& start_px, TagTemplateFit* fit) {
  if (target.type() != CalibrationTarget::Type::kAprilGrid || target.family() != "tag36h11") return false;
  std::array<Eigen::Vector2d, 4> board_corners;
  int have = 0;
  for (const TargetCorner& c : target.corners())
    if (c.id / 4 == tag) board_corners[c.id % 4] = c.point_in_target.head<2>(), ++have;
  if (have != 4) return false;
  const double cell_mm = target.tag_size_mm() / 8.0;

  // The start pose: InitialTargetPose on the four corners (a central approximation; the
  // fit then uses every pixel's own ray).
  double edge_px = 0.0;
  for (int k = 0; k < 4; ++k) edge_px = std::max(edge_px, (start_px[(k + 1) % 4] - start_px[k]).norm());
  if (!(edge_px >= 4.0 && edge_px <= 400.0)) return false;
  ImageDetections corners;
  for (int k = 0; k < 4; ++k) corners.corners.push_back({4 * tag + k, start_px[k]});
  TargetPose start_pose;
  if (!InitialTargetPose(sensor, target, corners, &start_pose)) return false;
  const Eigen::Matrix3d rotation = start_pose.camera_from_target_rotation.toRotationMatrix();  // camera_from_board
  const Eigen::Vector3d translation_mm = start_pose.camera_from_target_translation_mm;
  auto board_point = [&](const Eigen::Matrix3d& camera_from_board, const Eigen::Vector3d& board_origin_mm,
                         const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Eigen::Vector2d* at) {
    const Eigen::Vector3d normal = camera_from_board.col(2);
    const double along = normal.dot(direction);
    if (!(std::abs(along) > 1e-9)) return false;
    const double t = normal.dot(board_origin_mm - origin) / along;
    if (!(t > 0.0)) return false;
    *at = (camera_from_board.transpose() * (origin + t * direction - board_origin_mm)).head<2>();
    return true;
  };

  // A grid of pixels a cell and more around the square, with their rays; fitted are those
  // within one cell of the square at the start pose whose own ray and neighbours' meet the
  // mirror.
  FitPixels pixels;
  Eigen::Vector2d box_low = start_px[0], box_high = start_px[0];
  for (const Eigen::Vector2d& p : start_px) box_low = box_low.cwiseMin(p), box_high = box_high.cwiseMax(p);
  // One cell beyond the square, the blur's reach and the clearance around that.
  const double margin_px = 0.25 * edge_px + 4.0 + kRimClearancePx;
  const int u0 = std::max(0, static_cast<int>(std::floor(box_low.x() - margin_px)));
  const int v0 = std::max(0, static_cast<int>(std::floor(box_low.y() - margin_px)));
  const int u1 = std::min(grey.cols - 1, static_cast<int>(std::ceil(box_high.x() + margin_px)));
  const int v1 = std::min(grey.rows - 1, static_cast<int>(std::ceil(box_high.y() + margin_px)));
  if (u1 - u0 < 3 || v1 - v0 < 3) return false;
  const int width = u1 - u0 + 1, height = v1 - v0 + 1;
  Eigen::Matrix2Xd grid(2, width * height);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) grid.col(v * width + u) = Eigen::Vector2d(u0 + u, v0 + v);
  Eigen::Matrix3Xd grid_origins, grid_directions;
  std::vector<ProjectionStatus> statuses;
  sensor.UnprojectBatch(grid, &grid_origins, &grid_directions, &statuses);
  pixels.origins.resize(grid.cols());
  pixels.directions.resize(grid.cols());
  for (int i = 0; i < grid.cols(); ++i) pixels.origins[i] = grid_origins.col(i), pixels.directions[i] = grid_directions.col(i);
  // Pixels within kRimClearancePx of one whose ray misses the mirror (the rim, the camera
  // body's reflection) mix the board with the dark beyond in their blur and their box: they
  // are not fitted, and a tag with a corner that close is not fitted at all (a tag the
  // rim cuts put its corners 0.3 px off on a noise-free render).
  std::vector<char> clear(statuses.size(), 1);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      if (statuses[v * width + u] == ProjectionStatus::kOk) continue;
      for (int dv = -kRimClearancePx; dv <= kRimClearancePx; ++dv)
        for (int du = -kRimClearancePx; du <= kRimClearancePx; ++du)
          if (v + dv >= 0 && v + dv < height && u + du >= 0 && u + du < width) clear[(v + dv) * width + u + du] = 0;
    }
  for (const Eigen::Vector2d& corner : start_px) {
    const int u = static_cast<int>(std::lround(corner.x())) - u0, v = static_cast<int>(std::lround(corner.y())) - v0;
    if (u < 0 || v < 0 || u >= width || v >= height || !clear[v * width + u]) return false;
  }
  auto on_mirror = [&](int i) { return clear[i] != 0; };
  const Eigen::Vector2d low_mm = board_corners[0] - Eigen::Vector2d::Constant(cell_mm);
  const Eigen::Vector2d high_mm = board_corners[2] + Eigen::Vector2d::Constant(cell_mm);
  std::vector<Eigen::Vector2d> start_board;
  for (int v = 1; v + 1 < height; ++v)
    for (int u = 1; u + 1 < width; ++u) {
      const int i = v * width + u;
      std::array<int, 9> around;
      bool all_on_mirror = true;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          around[(dv + 1) * 3 + du + 1] = i + dv * width + du;
          all_on_mirror = all_on_mirror && on_mirror(i + dv * width + du);
        }
      if (!all_on_mirror) continue;
      // The pixel's and its neighbours' rays must meet the plane in front (the cost refuses
      // a step where one does not, and from the start none may); around[4] is the pixel.
      Eigen::Vector2d at;
      bool all_meet = true;
      for (int j = 0; j < 9 && all_meet; ++j)
        if (j != 4) all_meet = board_point(rotation, translation_mm, pixels.origins[around[j]], pixels.directions[around[j]], &at);
      if (!all_meet || !board_point(rotation, translation_mm, pixels.origins[i], pixels.directions[i], &at)) continue;
      if ((at.array() < low_mm.array()).any() || (at.array() > high_mm.array()).any()) continue;
      pixels.grey.push_back(grey.at<uint8_t>(v0 + v, u0 + u));
      pixels.rays.push_back(around);
      start_board.push_back(at);
    }
  // Several pixels per parameter.
  if (pixels.grey.size() < 60) return false;
  // A large tag holds thousands of pixels, far more than its 9 parameters need: every
  // k-th (raster order) keeps its time near a small one's.
  if (const size_t stride = (pixels.grey.size() + kMaxPixels - 1) / kMaxPixels; stride > 1) {
    size_t kept = 0;
    for (size_t i = 0; i < pixels.grey.size(); i += stride, ++kept) {
      pixels.grey[kept] = pixels.grey[i];
      pixels.rays[kept] = pixels.rays[i];
      start_board[kept] = start_board[i];
    }
    pixels.grey.resize(kept);
    pixels.rays.resize(kept);
    start_board.resize(kept);
  }

  // Ink within reach of each pixel (3 cells: the blur and the fit's moves stay well within).
  const double reach_mm = 3.0 * cell_mm;
  std::vector<Eigen::Vector4d> rectangles;
  for (const Eigen::Vector4d& r : target.InkRectangles())
    if (r(0) < high_mm.x() + reach_mm && r(0) + r(2) > low_mm.x() - reach_mm && r(1) < high_mm.y() + reach_mm &&
        r(1) + r(3) > low_mm.y() - reach_mm)
      rectangles.push_back(r);
  pixels.rectangle_begin.push_back(0);
  for (const Eigen::Vector2d& at : start_board) {
    for (size_t k = 0; k < rectangles.size(); ++k) {
      const Eigen::Vector4d& r = rectangles[k];
      if (at.x() > r(0) - reach_mm && at.x() < r(0) + r(2) + reach_mm && at.y() > r(1) - reach_mm &&
          at.y() < r(1) + r(3) + reach_mm)
        pixels.rectangles.push_back(static_cast<int>(k));
    }
    pixels.rectangle_begin.push_back(static_cast<int>(pixels.rectangles.size()));
  }

  std::vector<double> sorted = pixels.grey;
  std::sort(sorted.begin(), sorted.end());
  double parameters[kNumParams];
  const Eigen::AngleAxisd angle_axis(rotation);
  const Eigen::Vector3d rotation_vector = angle_axis.angle() * angle_axis.axis();
  for (int k = 0; k < 3; ++k) parameters[k] = rotation_vector[k], parameters[3 + k] = translation_mm[k];
  parameters[6] = std::log(0.8);
  parameters[7] = sorted[sorted.size() / 10];
  parameters[8] = sorted[sorted.size() * 9 / 10];

  // One residual per pixel under a Cauchy loss at a tenth of the contrast: pixels the
  // pattern does not explain (the dark beyond a rim the sensor places too far out, a
  // finger on the board, a glint) weigh little.
  ceres::CauchyLoss loss(0.1 * std::max(parameters[8] - parameters[7], 1.0));  // outlives the problem
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (size_t i = 0; i < pixels.grey.size(); ++i)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<TagResidual, 1, kNumParams>(new TagResidual(pixels, rectangles, i)),
                             &loss, parameters);
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  // A fit still creeping after 50 iterations is judged like any other, by the checks below.
  if (!summary.IsSolutionUsable()) return false;

  TagTemplateFit result;
  result.blur_px = std::exp(parameters[6]);
  result.contrast = parameters[8] - parameters[7];
  result.pixels = static_cast<int>(pixels.grey.size());
  ceres::Problem::EvaluateOptions plain;
  plain.apply_loss_function = false;
  double plain_cost = 0.0;
  if (!problem.Evaluate(plain, &plain_cost, nullptr, nullptr, nullptr)) return false;
  result.rms_grey = std::sqrt(2.0 * plain_cost / pixels.grey.size());
  if (!(result.contrast >= 20.0) || !(result.blur_px >= 0.1 && result.blur_px <= 4.0) ||
      !(result.rms_grey <= 0.25 * result.contrast))
    return false;
  const Eigen::Vector3d fitted_rotation_vector(parameters[0], parameters[1], parameters[2]);
  const double angle = fitted_rotation_vector.norm();
  const Eigen::Matrix3d fitted_rotation =
      angle > 0.0 ? Eigen::AngleAxisd(angle, fitted_rotation_vector / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d fitted_translation_mm(parameters[3], parameters[4], parameters[5]);
  // Half a cell of the tag's longest side. Along its most foreshortened side that is more
  // than a cell, but where the edge profiles failed the start is the detector's corner, off
  // by ~1 px radially near the rim (a bound of half a short cell, at least 1 px, refused 5
  // good rim tags on the realistic set); a fit one bit column over there shows in its
  // residual, which the caller compares with the image's other tags.
  const double cell_px = edge_px / 8.0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d corner_in_camera = fitted_rotation * Eigen::Vector3d(board_corners[k].x(), board_corners[k].y(), 0.0) +
                                             fitted_translation_mm;
    if (sensor.Project(corner_in_camera, &result.corners_px[k]) != ProjectionStatus::kOk) return false;
    if (!((result.corners_px[k] - start_px[k]).norm() <= 0.5 * std::max(cell_px, 1.0))) return false;
  }
  *fit = result;
  return true;
}

}  // namespace omnical
