#include "calib/printed_patch_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

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
  // Signed distance inside the mirror's rim, omni px (+inf where the rim is not modelled).
  std::vector<double> inside_rim_px;
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

// Parameters: the piece's plane pose, camera_from_board (angle-axis, 3; translation mm, 3);
// log sigma_px; ink and paper levels. The rim's (held where it is not modelled): its shift
// outwards from the sensor's, omni px; the level beyond it.
constexpr int kNumParams = 9;
constexpr int kNumRimParams = 2;
// With the rim modelled, pixels up to this far beyond it are fitted: the blur's reach.
constexpr double kBeyondRimPx = 4.0;
constexpr double kMaxRimShiftPx = 3.0;
// Fitted pixels a region's core needs to be judged (and the piece kept).
constexpr int kMinCorePixels = 20;

// Where a ray (origin o, direction d, camera frame) meets the board at pose
// camera_from_board (row-major rotation, centre mm), in board mm (x, y): its plane, then two
// Newton steps onto the warped surface (a sag of mm over a board of hundreds: the second
// step moves it by well under a micrometre). False when the ray runs along the plane or
// meets it behind its origin (Ceres then refuses the step).
template <typename T>
bool RayOnBoard(const T* rotation, const T* centre, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                const WarpedSurface& surface, T* x, T* y) {
  const bool warped = !surface.warp.IsZero();
  const Eigen::Vector2d mid_mm = 0.5 * (surface.low_mm + surface.high_mm);
  const Eigen::Vector2d half_mm = (0.5 * (surface.high_mm - surface.low_mm)).cwiseMax(1e-9);
  // The ray in the board frame: a + t b.
  const T ox = T(o.x()) - centre[0], oy = T(o.y()) - centre[1], oz = T(o.z()) - centre[2];
  T a[3], b[3];
  for (int k = 0; k < 3; ++k) {
    a[k] = rotation[k] * ox + rotation[3 + k] * oy + rotation[6 + k] * oz;
    b[k] = rotation[k] * d.x() + rotation[3 + k] * d.y() + rotation[6 + k] * d.z();
  }
  if (!(std::abs(ScalarPart(b[2])) > 1e-9)) return false;
  T t = -a[2] / b[2];
  for (int step = 0; warped && step < 2; ++step) {
    const T u = (a[0] + t * b[0] - T(mid_mm.x())) / T(half_mm.x()), v = (a[1] + t * b[1] - T(mid_mm.y())) / T(half_mm.y());
    const T sag = T(surface.warp.x_mm) * (T(1.0) - u * u) + T(surface.warp.y_mm) * (T(1.0) - v * v);
    const T slope_x = T(-2.0 * surface.warp.x_mm / half_mm.x()) * u, slope_y = T(-2.0 * surface.warp.y_mm / half_mm.y()) * v;
    const T along = b[2] - slope_x * b[0] - slope_y * b[1];
    if (!(std::abs(ScalarPart(along)) > 1e-9)) return false;
    t -= (a[2] + t * b[2] - sag) / along;
  }
  if (!(ScalarPart(t) > 0.0)) return false;
  *x = a[0] + t * b[0];
  *y = a[1] + t * b[1];
  return true;
}

// A value whose derivatives by the pose p[0..5] are `gradient`, as a T: the chain rule
// through p's own derivatives (a Jet), or the value (a double).
inline double WithPoseGradient(double value, const double* /*gradient*/, const double* /*p*/) { return value; }
template <int N>
ceres::Jet<double, N> WithPoseGradient(double value, const double* gradient, const ceres::Jet<double, N>* p) {
  ceres::Jet<double, N> out(value);
  for (int k = 0; k < 6; ++k) out.v += gradient[k] * p[k].v;
  return out;
}

// The fitted pixels' rays on the board at Ceres' evaluation point, with their derivatives
// by the pose, once per evaluation: each ray serves the residuals of up to 9 pixels (the
// 3 x 3 around each), intersected in every one of them, in Jets of all the fit's parameters.
class RaysOnBoard : public ceres::EvaluationCallback {
 public:
  // `pose`: the problem's parameter block (its first 6 values are the pose).
  RaysOnBoard(const FitPixels& pixels, const WarpedSurface& surface, const double* pose)
      : pixels_(pixels), surface_(surface), pose_(pose), points_(pixels.origins.size()) {
    std::vector<char> used(pixels.origins.size(), 0);
    for (const std::array<int, 9>& around : pixels.rays)
      for (int ray : around) used[ray] = 1;
    for (size_t ray = 0; ray < used.size(); ++ray)
      if (used[ray]) used_.push_back(static_cast<int>(ray));
  }

  void PrepareForEvaluation(bool /*evaluate_jacobians*/, bool new_evaluation_point) override {
    if (valid_ && !new_evaluation_point) return;
    using Jet6 = ceres::Jet<double, 6>;
    Jet6 p[6];
    for (int k = 0; k < 6; ++k) p[k] = Jet6(pose_[k], k), at_pose_[k] = pose_[k];
    Jet6 rotation[9];  // row-major camera_from_board
    ceres::AngleAxisToRotationMatrix(p, ceres::RowMajorAdapter3x3(rotation));
    for (int ray : used_) {
      Point& point = points_[ray];
      Jet6 x, y;
      point.ok = RayOnBoard(rotation, p + 3, pixels_.origins[ray], pixels_.directions[ray], surface_, &x, &y);
      if (!point.ok) continue;
      point.x = x.a, point.y = y.a;
      for (int k = 0; k < 6; ++k) point.dx[k] = x.v[k], point.dy[k] = y.v[k];
    }
    valid_ = true;
  }

  // Ray `ray` on the board at pose p[0..5]; false where it misses the board. Computed
  // afresh should p not be the point prepared (Ceres promises it is).
  template <typename T>
  bool At(int ray, const T* p, T* x, T* y) const {
    bool prepared = valid_;
    for (int k = 0; k < 6 && prepared; ++k) prepared = ScalarPart(p[k]) == at_pose_[k];
    if (!prepared) {
      T rotation[9];
      ceres::AngleAxisToRotationMatrix(p, ceres::RowMajorAdapter3x3(rotation));
      return RayOnBoard(rotation, p + 3, pixels_.origins[ray], pixels_.directions[ray], surface_, x, y);
    }
    const Point& point = points_[ray];
    if (!point.ok) return false;
    *x = WithPoseGradient(point.x, point.dx, p);
    *y = WithPoseGradient(point.y, point.dy, p);
    return true;
  }

 private:
  struct Point {
    bool ok = false;
    double x = 0.0, y = 0.0, dx[6] = {}, dy[6] = {};
  };
  const FitPixels& pixels_;
  const WarpedSurface& surface_;
  const double* pose_;
  std::vector<Point> points_;  // per grid ray; those of used_ filled
  std::vector<int> used_;
  double at_pose_[6] = {};
  bool valid_ = false;
};

// The standard normal CDF and its density at z, from one exp: erfc by Abramowitz & Stegun
// 7.1.26 (absolute error under 1.5e-7, a 4e-5 grey-level step on a full-range edge). The
// library's erfc and the exp of its derivative took a fifth of the whole-tag fits' time.
inline double NormalCdf(double z, double* density) {
  const double w = std::abs(z) * M_SQRT1_2;
  const double t = 1.0 / (1.0 + 0.3275911 * w);
  const double gauss = std::exp(-w * w);
  const double tail =
      0.5 * gauss * t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  *density = gauss * (0.5 * M_2_SQRTPI * M_SQRT1_2);
  return z < 0.0 ? tail : 1.0 - tail;
}
inline double NormalCdf(double z) {
  double density;
  return NormalCdf(z, &density);
}
template <int N>
ceres::Jet<double, N> NormalCdf(const ceres::Jet<double, N>& z) {
  double density;
  const double value = NormalCdf(z.a, &density);
  return ceres::Jet<double, N>(value, density * z.v);
}

// The blurred step at each ink edge along one board axis, P(coordinate blurred by sigma <
// edge), for one quadrature node: 0 or 1 beyond `reach` (6 sigma: under 1e-9 off), else
// computed once per edge (a tag's rows of ink share their edges). The CDF and its
// density took a third of the fit's time.
template <typename T>
class EdgeCdfs {
 public:
  T At(double edge, const T& coordinate, const T& sigma, double reach) {
    const double from_edge = edge - ScalarPart(coordinate);
    if (from_edge > reach) return T(1.0);
    if (from_edge < -reach) return T(0.0);
    for (int k = 0; k < count_; ++k)
      if (std::abs(edge_[k] - edge) < 1e-9) return value_[k];
    const T value = NormalCdf((T(edge) - coordinate) / sigma);
    if (count_ < kMaxEdges) edge_[count_] = edge, value_[count_++] = value;
    return value;
  }

 private:
  static constexpr int kMaxEdges = 8;
  double edge_[kMaxEdges];
  T value_[kMaxEdges];
  int count_ = 0;
};

// The residual of one fitted pixel, given the rim's parameters (shift px, level beyond).
class PatchResidual {
 public:
  // The residual of fitted pixel `i`.
  PatchResidual(const FitPixels& pixels, const std::vector<Eigen::Vector4d>& rectangles, const RaysOnBoard& rays, size_t i)
      : pixels_(pixels), rectangles_(rectangles), rays_(rays), i_(i) {}

  template <typename T>
  bool operator()(const T* p, const T* rim, T* residuals) const {
    return Evaluate(p, rim, residuals);
  }

  // The same, `rim` a T or a double (held).
  template <typename T, typename RimT>
  bool Evaluate(const T* p, const RimT* rim, T* residuals) const {
    using std::exp;
    using std::sqrt;
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
      if (!rays_.At(ray[j], p, &bx[j], &by[j])) return false;
    // pixel -> board to second order: board mm per omni px along u (a, c) and v (b, d),
    // and the second derivatives.
    const T a = T(0.5) * (bx[5] - bx[3]), c = T(0.5) * (by[5] - by[3]), b = T(0.5) * (bx[7] - bx[1]),
            d = T(0.5) * (by[7] - by[1]);
    const T uu_x = bx[5] + bx[3] - T(2.0) * bx[4], uu_y = by[5] + by[3] - T(2.0) * by[4];
    const T vv_x = bx[7] + bx[1] - T(2.0) * bx[4], vv_y = by[7] + by[1] - T(2.0) * by[4];
    const T uv_x = T(0.25) * (bx[8] - bx[6] - bx[2] + bx[0]), uv_y = T(0.25) * (by[8] - by[6] - by[2] + by[0]);
    const T sx = sqrt(residual_variance * (a * a + b * b)), sy = sqrt(residual_variance * (c * c + d * d));
    // Ink within 6 sigma on both axes (farther it adds under 1e-9): tested on the scalar
    // parts before any CDF of a Jet.
    const double reach_x = 6.0 * ScalarPart(sx), reach_y = 6.0 * ScalarPart(sy);
    T coverage(0.0);
    for (int ju = 0; ju < 3; ++ju)
      for (int jv = 0; jv < 3; ++jv) {
        const T du = T(ju - 1) * node_px, dv = T(jv - 1) * node_px;
        const T x = bx[4] + a * du + b * dv + T(0.5) * (uu_x * du * du + vv_x * dv * dv) + uv_x * du * dv;
        const T y = by[4] + c * du + d * dv + T(0.5) * (uu_y * du * du + vv_y * dv * dv) + uv_y * du * dv;
        const double x0 = ScalarPart(x), y0 = ScalarPart(y);
        EdgeCdfs<T> x_edges, y_edges;
        T ink_here(0.0);
        for (int k = pixels_.rectangle_begin[i]; k < pixels_.rectangle_begin[i + 1]; ++k) {
          const Eigen::Vector4d& r = rectangles_[pixels_.rectangles[k]];
          if (x0 < r(0) - reach_x || x0 > r(0) + r(2) + reach_x || y0 < r(1) - reach_y || y0 > r(1) + r(3) + reach_y)
            continue;
          ink_here += (x_edges.At(r(0) + r(2), x, sx, reach_x) - x_edges.At(r(0), x, sx, reach_x)) *
                      (y_edges.At(r(1) + r(3), y, sy, reach_y) - y_edges.At(r(1), y, sy, reach_y));
        }
        coverage += T(kNodeWeights[ju] * kNodeWeights[jv]) * ink_here;
      }
    if (coverage > T(1.0)) coverage = T(1.0);
    T board_grey = paper + (ink - paper) * coverage;
    // The rim: the board's reflection gives way to the level beyond it, blurred like the
    // board (the product of the two blurred is the blur of the product to first order).
    if (std::isfinite(pixels_.inside_rim_px[i])) {
      const T on_mirror = NormalCdf((T(pixels_.inside_rim_px[i]) + rim[0]) / sqrt(variance_px2));
      board_grey = T(rim[1]) + (board_grey - T(rim[1])) * on_mirror;
    }
    residuals[0] = board_grey - T(pixels_.grey[i]);
    // A degenerate step (rays meeting the board at one point, a Newton step along the
    // surface) fails the step rather than handing Ceres a NaN, which it would log.
    using ceres::isfinite;
    using std::isfinite;
    return isfinite(residuals[0]);
  }

 private:
  const FitPixels& pixels_;
  const std::vector<Eigen::Vector4d>& rectangles_;
  const RaysOnBoard& rays_;
  size_t i_;
};

// PatchResidual with the rim's parameters held (most pieces: no rim within reach), so that
// the Jets carry the 9 parameters alone.
class HeldRimPatchResidual {
 public:
  HeldRimPatchResidual(const PatchResidual& residual, const double* rim) : residual_(residual), rim_(rim) {}

  template <typename T>
  bool operator()(const T* p, T* residuals) const {
    return residual_.Evaluate(p, rim_, residuals);
  }

 private:
  PatchResidual residual_;
  const double* rim_;
};

// The radius of a reflection point (camera frame) about the mirror's axis, mm.
double MirrorRadiusMm(const Sensor& sensor, const Eigen::Vector3d& point_in_camera_mm) {
  return sensor.cache().InMirrorFrame(point_in_camera_mm).head<2>().norm();
}

// How far inside the rim (omni px) a point of mirror radius radius_mm is, the radius
// changing by (dr_du, dr_dv) mm per px there.
double RimDistancePx(double rim_mm, double radius_mm, double dr_du, double dr_dv) {
  return (rim_mm - radius_mm) / std::hypot(dr_du, dr_dv);
}

}  // namespace

double InsideRimPx(const Sensor& sensor, const Sensor& wider, const Eigen::Vector2d& pixel) {
  double radius_mm[5];  // at pixel + (0, 0), (-1, 0), (1, 0), (0, -1), (0, 1)
  const Eigen::Vector2d steps[5] = {{0.0, 0.0}, {-1.0, 0.0}, {1.0, 0.0}, {0.0, -1.0}, {0.0, 1.0}};
  for (int k = 0; k < 5; ++k) {
    Eigen::Vector3d origin, direction;
    if (wider.Unproject(pixel + steps[k], &origin, &direction) != ProjectionStatus::kOk) return std::nan("");
    radius_mm[k] = MirrorRadiusMm(sensor, origin);
  }
  return RimDistancePx(sensor.rim_radius_mm(), radius_mm[0], 0.5 * (radius_mm[2] - radius_mm[1]),
                       0.5 * (radius_mm[4] - radius_mm[3]));
}

bool OnMirrorWithMargin(const Sensor& sensor, const Eigen::Vector2d& pixel, int margin_px) {
  for (int dv = -margin_px; dv <= margin_px; ++dv)
    for (int du = -margin_px; du <= margin_px; ++du) {
      Eigen::Vector3d origin, direction;
      if (sensor.Unproject(pixel + Eigen::Vector2d(du, dv), &origin, &direction) != ProjectionStatus::kOk) return false;
    }
  return true;
}

bool FitPrintedPatch(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, const BoardWarp& warp,
                     const TargetPose& start, const PatchRegion& region, PatchFit* fit) {
  const WarpedSurface surface = WarpedSurface::Of(target, warp);
  const Eigen::Matrix3d rotation = start.camera_from_target_rotation.toRotationMatrix();  // camera_from_board
  const Eigen::Vector3d translation_mm = start.camera_from_target_translation_mm;
  // Pixels are chosen where their rays meet the start pose's plane (the warp moves them by
  // well under a pixel).
  WarpedSurface plane = surface;
  plane.warp = BoardWarp();
  double start_rotation[9];  // row-major camera_from_board
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>{start_rotation} = rotation;
  auto board_point = [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Eigen::Vector2d* at) {
    return RayOnBoard(start_rotation, translation_mm.data(), origin, direction, plane, &at->x(), &at->y());
  };

  // A grid of pixels over the image box, with their rays; fitted are those whose ray meets
  // the start plane within the board box and whose own ray and neighbours' meet the mirror.
  FitPixels pixels;
  const int u0 = std::max(0, static_cast<int>(std::floor(region.image_low_px.x())));
  const int v0 = std::max(0, static_cast<int>(std::floor(region.image_low_px.y())));
  const int u1 = std::min(grey.cols - 1, static_cast<int>(std::ceil(region.image_high_px.x())));
  const int v1 = std::min(grey.rows - 1, static_cast<int>(std::ceil(region.image_high_px.y())));
  if (!(u1 - u0 >= 3 && v1 - v0 >= 3)) return false;
  const int width = u1 - u0 + 1, height = v1 - v0 + 1;
  Eigen::Matrix2Xd grid(2, width * height);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) grid.col(v * width + u) = Eigen::Vector2d(u0 + u, v0 + v);
  Eigen::Matrix3Xd grid_origins, grid_directions;
  std::vector<ProjectionStatus> statuses;
  // With the rim modelled, the rays of pixels a little beyond it too (a wider mirror of the
  // same shape): the blur mixes their board with the dark.
  std::optional<Sensor> wider;
  if (region.model_rim) wider = SensorWithWiderRim(sensor, 1.15);
  const Sensor& ray_sensor = region.model_rim ? *wider : sensor;
  ray_sensor.UnprojectBatch(grid, &grid_origins, &grid_directions, &statuses);
  pixels.origins.resize(grid.cols());
  pixels.directions.resize(grid.cols());
  for (int i = 0; i < grid.cols(); ++i) pixels.origins[i] = grid_origins.col(i), pixels.directions[i] = grid_directions.col(i);
  // On the mirror; with the rim modelled, the signed distance inside it, omni px: the
  // reflection point's radius short of the rim's, over its gradient across the image.
  std::vector<char> inside(statuses.size(), 0);
  std::vector<double> inside_rim_px(statuses.size(), HUGE_VAL);
  if (region.model_rim) {
    std::vector<double> radius_mm(statuses.size(), std::nan(""));
    for (size_t i = 0; i < statuses.size(); ++i)
      if (statuses[i] == ProjectionStatus::kOk) radius_mm[i] = MirrorRadiusMm(sensor, pixels.origins[i]);
    for (int v = 1; v + 1 < height; ++v)
      for (int u = 1; u + 1 < width; ++u) {
        const int i = v * width + u;
        const double du = 0.5 * (radius_mm[i + 1] - radius_mm[i - 1]), dv = 0.5 * (radius_mm[i + width] - radius_mm[i - width]);
        inside_rim_px[i] = RimDistancePx(sensor.rim_radius_mm(), radius_mm[i], du, dv);  // NaN without all four
      }
    for (size_t i = 0; i < statuses.size(); ++i) inside[i] = statuses[i] == ProjectionStatus::kOk && radius_mm[i] <= sensor.rim_radius_mm();
  } else {
    for (size_t i = 0; i < statuses.size(); ++i) inside[i] = statuses[i] == ProjectionStatus::kOk;
  }
  // Pixels near one whose ray misses the mirror are not fitted (kRimClearancePx); with the
  // rim modelled, only near one whose ray misses the wider mirror (the camera body's
  // reflection), and those up to kBeyondRimPx beyond the rim are.
  std::vector<char> clear(statuses.size(), 1);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      if (statuses[v * width + u] == ProjectionStatus::kOk) continue;
      for (int dv = -kRimClearancePx; dv <= kRimClearancePx; ++dv)
        for (int du = -kRimClearancePx; du <= kRimClearancePx; ++du)
          if (v + dv >= 0 && v + dv < height && u + du >= 0 && u + du < width) clear[(v + dv) * width + u + du] = 0;
    }
  auto index_of = [&](const Eigen::Vector2d& pixel) {
    const int u = static_cast<int>(std::lround(pixel.x())) - u0, v = static_cast<int>(std::lround(pixel.y())) - v0;
    return u < 0 || v < 0 || u >= width || v >= height ? -1 : v * width + u;
  };
  for (const Eigen::Vector2d& pixel : region.clear_px)
    if (const int i = index_of(pixel); i < 0 || !clear[i]) return false;
  for (const Eigen::Vector2d& pixel : region.on_mirror_px)
    if (const int i = index_of(pixel); i < 0 || !inside[i]) return false;
  auto on_mirror = [&](int i) {
    return clear[i] != 0 && (!region.model_rim || inside_rim_px[i] >= -kBeyondRimPx);  // false for NaN
  };
  const Eigen::Vector2d& low_mm = region.board_low_mm;
  const Eigen::Vector2d& high_mm = region.board_high_mm;
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
        if (j != 4) all_meet = board_point(pixels.origins[around[j]], pixels.directions[around[j]], &at);
      if (!all_meet || !board_point(pixels.origins[i], pixels.directions[i], &at)) continue;
      if ((at.array() < low_mm.array()).any() || (at.array() > high_mm.array()).any()) continue;
      pixels.grey.push_back(grey.at<uint8_t>(v0 + v, u0 + u));
      pixels.inside_rim_px.push_back(inside_rim_px[i]);
      pixels.rays.push_back(around);
      start_board.push_back(at);
    }
  // Several pixels per parameter.
  if (pixels.grey.size() < 60) return false;
  // A large piece holds thousands of pixels, far more than its 9 parameters need: every
  // k-th (raster order) keeps its time near a small one's.
  if (const size_t stride = (pixels.grey.size() + kMaxPixels - 1) / kMaxPixels; stride > 1) {
    size_t kept = 0;
    for (size_t i = 0; i < pixels.grey.size(); i += stride, ++kept) {
      pixels.grey[kept] = pixels.grey[i];
      pixels.inside_rim_px[kept] = pixels.inside_rim_px[i];
      pixels.rays[kept] = pixels.rays[i];
      start_board[kept] = start_board[i];
    }
    pixels.grey.resize(kept);
    pixels.inside_rim_px.resize(kept);
    pixels.rays.resize(kept);
    start_board.resize(kept);
  }

  // Ink within reach of each pixel: 0.3 of the board box's longer side (a tag's box is 10
  // cells: 3 cells; a junction's 2.5 squares: 0.75), the blur and the fit's moves well within.
  const double reach_mm = 0.3 * (high_mm - low_mm).maxCoeff();
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

  // The levels start from the pixels well inside the rim (ink, paper) and beyond it.
  std::vector<double> sorted, beyond;
  for (size_t i = 0; i < pixels.grey.size(); ++i)
    (pixels.inside_rim_px[i] >= 2.0 ? sorted : beyond).push_back(pixels.grey[i]);
  if (sorted.size() < 30) return false;
  std::sort(sorted.begin(), sorted.end());
  double parameters[kNumParams];
  const Eigen::AngleAxisd angle_axis(rotation);
  const Eigen::Vector3d rotation_vector = angle_axis.angle() * angle_axis.axis();
  for (int k = 0; k < 3; ++k) parameters[k] = rotation_vector[k], parameters[3 + k] = translation_mm[k];
  parameters[6] = std::log(0.8);
  parameters[7] = sorted[sorted.size() / 10];
  parameters[8] = sorted[sorted.size() * 9 / 10];
  double rim[kNumRimParams] = {0.0, parameters[7]};  // shift bounded both ways (kMaxRimShiftPx)
  if (!beyond.empty()) {
    std::nth_element(beyond.begin(), beyond.begin() + beyond.size() / 2, beyond.end());
    rim[1] = beyond[beyond.size() / 2];
  }

  // One residual per pixel under a Cauchy loss at a tenth of the contrast: pixels the
  // pattern does not explain (the dark beyond a rim the sensor places too far out, a
  // finger on the board, a glint) weigh little.
  ceres::CauchyLoss loss(0.1 * std::max(parameters[8] - parameters[7], 1.0));  // outlives the problem
  RaysOnBoard rays(pixels, surface, parameters);  // outlives the problem
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.evaluation_callback = &rays;
  ceres::Problem problem(problem_options);
  // The rim's parameters held where no fitted pixel is within the blur's reach of it.
  const double nearest_rim_px = pixels.inside_rim_px.empty() ? HUGE_VAL : *std::min_element(pixels.inside_rim_px.begin(), pixels.inside_rim_px.end());
  const bool rim_held = !region.model_rim || !(nearest_rim_px < 8.0);
  for (size_t i = 0; i < pixels.grey.size(); ++i) {
    const PatchResidual residual(pixels, rectangles, rays, i);
    if (rim_held)
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<HeldRimPatchResidual, 1, kNumParams>(
                                   new HeldRimPatchResidual(residual, rim)),
                               &loss, parameters);
    else
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PatchResidual, 1, kNumParams, kNumRimParams>(
                                   new PatchResidual(residual)),
                               &loss, parameters, rim);
  }
  if (!rim_held) {
    // A sensor's rim within a few px of the image's: farther, the shift would take over
    // the piece's own edge.
    problem.SetParameterLowerBound(rim, 0, -kMaxRimShiftPx);
    problem.SetParameterUpperBound(rim, 0, kMaxRimShiftPx);
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  // Where the sensor is only an approximation (an unknown mirror's first fit), fits creep
  // on towards the 50-iteration cap: stopping when a step gains under 1e-5 of the cost
  // (Ceres' default 1e-6) took calibrate on ohte-sph-misaligned-near without a guess from
  // 14.5 to 10.8 s and moved its 1103 corners by 0.0006 px RMS (0.014 px at most); with a
  // guess by 0.001 px RMS, their error from the truth unchanged (0.0415 px).
  options.function_tolerance = 1e-5;
  // The rim shift's bounds made Ceres line-search along each projected step, a Jacobian
  // per trial (253 in a rim tag's 36 iterations); without, the projected step is taken or
  // refused like any other (the realistic aprilgrid set's corners moved under 0.001 px).
  options.max_num_line_search_step_size_iterations = 0;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  // A fit still creeping after 50 iterations is judged like any other, by the checks below.
  if (!summary.IsSolutionUsable()) return false;

  PatchFit result;
  result.blur_px = std::exp(parameters[6]);
  result.contrast = parameters[8] - parameters[7];
  result.pixels = static_cast<int>(pixels.grey.size());
  result.rim_shift_px = rim_held || !(rim[0] < kMaxRimShiftPx - 1e-6) ? 0.0 : rim[0];
  ceres::Problem::EvaluateOptions plain;
  plain.apply_loss_function = false;
  double plain_cost = 0.0;
  std::vector<double> residuals;  // per fitted pixel, in their order
  if (!problem.Evaluate(plain, &plain_cost, &residuals, nullptr, nullptr)) return false;
  result.rms_grey = std::sqrt(2.0 * plain_cost / pixels.grey.size());
  if (!(result.contrast >= 20.0) || !(result.blur_px >= 0.1 && result.blur_px <= 4.0) ||
      !(result.rms_grey <= 0.25 * result.contrast))
    return false;
  // The core must match on its own: a finger over it is a small share of the whole piece.
  if (region.core_high_mm.x() > region.core_low_mm.x()) {
    double core_sum = 0.0;
    int core_pixels = 0;
    for (size_t i = 0; i < residuals.size(); ++i)
      if ((start_board[i].array() >= region.core_low_mm.array()).all() &&
          (start_board[i].array() <= region.core_high_mm.array()).all())
        core_sum += residuals[i] * residuals[i], ++core_pixels;
    if (core_pixels < kMinCorePixels || !(std::sqrt(core_sum / core_pixels) <= 0.25 * result.contrast)) return false;
  }
  const Eigen::Vector3d fitted_rotation_vector(parameters[0], parameters[1], parameters[2]);
  const double angle = fitted_rotation_vector.norm();
  result.pose.camera_from_target_rotation =
      angle > 0.0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, fitted_rotation_vector / angle)) : Eigen::Quaterniond::Identity();
  result.pose.camera_from_target_translation_mm = Eigen::Vector3d(parameters[3], parameters[4], parameters[5]);
  *fit = result;
  return true;
}

}  // namespace omnical
