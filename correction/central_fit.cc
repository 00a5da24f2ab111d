#include "correction/central_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "correction/remap_table.h"

namespace omnical {

namespace {

// The mirror-reversed frames of central_fit.h (determinant -1).
Eigen::Matrix3d MeiFlip() { return Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal(); }
Eigen::Matrix3d OCamFlip() {
  Eigen::Matrix3d m;
  m << 0, 1, 0, 1, 0, 0, 0, 0, 1;
  return m;
}

// central_from_mirror = flip * R(tilt_x, tilt_y): the tilt lets a misaligned sensor's
// image centre move off the mirror axis.
template <typename T>
void ToCentral(const Eigen::Matrix3d& flip, const T* tilt, const Eigen::Vector3d& offset, T* out) {
  const T angle_axis[3] = {tilt[0], tilt[1], T(0.0)};
  const T in[3] = {T(offset.x()), T(offset.y()), T(offset.z())};
  T rotated[3];
  ceres::AngleAxisRotatePoint(angle_axis, in, rotated);
  for (int r = 0; r < 3; ++r) out[r] = T(flip(r, 0)) * rotated[0] + T(flip(r, 1)) * rotated[1] + T(flip(r, 2)) * rotated[2];
}

Eigen::Matrix3d CentralFromMirror(const Eigen::Matrix3d& flip, const double* tilt) {
  Eigen::Matrix3d m;
  for (int c = 0; c < 3; ++c) {
    double column[3];
    ToCentral(flip, tilt, Eigen::Vector3d::Unit(c), column);
    m.col(c) << column[0], column[1], column[2];
  }
  return m;
}

// cv::omnidir::projectPoints (Mei): unit sphere, re-projection from (0, 0, -xi), radial and
// tangential distortion, K with skew. intrinsics: fx fy cx cy skew xi k1 k2 p1 p2.
template <typename T>
bool MeiProject(const T* intrinsics, const T* point, T* pixel) {
  const T norm = sqrt(point[0] * point[0] + point[1] * point[1] + point[2] * point[2]);
  const T denominator = point[2] / norm + intrinsics[5];
  if (!(denominator > T(1e-9))) return false;
  const T x = point[0] / norm / denominator, y = point[1] / norm / denominator;
  const T r2 = x * x + y * y, radial = T(1.0) + intrinsics[6] * r2 + intrinsics[7] * r2 * r2;
  const T xd = x * radial + T(2.0) * intrinsics[8] * x * y + intrinsics[9] * (r2 + T(2.0) * x * x);
  const T yd = y * radial + intrinsics[8] * (r2 + T(2.0) * y * y) + T(2.0) * intrinsics[9] * x * y;
  pixel[0] = intrinsics[0] * xd + intrinsics[4] * yd + intrinsics[2];
  pixel[1] = intrinsics[1] * yd + intrinsics[3];
  return true;
}

struct MeiResidual {
  Eigen::Vector3d offset;  // point - V0, mirror frame
  Eigen::Vector2d pixel;
  template <typename T>
  bool operator()(const T* intrinsics, const T* tilt, T* residual) const {
    T point[3], projected[2];
    ToCentral(MeiFlip(), tilt, offset, point);
    if (!MeiProject(intrinsics, point, projected)) return false;
    residual[0] = projected[0] - T(pixel.x());
    residual[1] = projected[1] - T(pixel.y());
    return true;
  }
};

// OCamCalib's cam2world direction of an image point, compared with the sample's direction
// (both unit) and scaled by the sensor's px per rad there: ~ px.
// centre: xc yc c d e; pol: a0 a2 a3 ... a13 of rho / rho_scale (a1 = 0, as OCamCalib
// fixes it; unused degrees held at 0).
constexpr int kOCamMaxDegree = 13;
struct OCamResidual {
  Eigen::Vector3d offset;
  Eigen::Vector2d pixel;  // (col, row)
  double px_per_rad, rho_scale;
  template <typename T>
  bool operator()(const T* centre, const T* pol, const T* tilt, T* residual) const {
    const T row = T(pixel.y()) - centre[0], col = T(pixel.x()) - centre[1];
    const T inverse_det = T(1.0) / (centre[2] - centre[3] * centre[4]);
    const T xp = inverse_det * (row - centre[3] * col), yp = inverse_det * (-centre[4] * row + centre[2] * col);
    const T rho = sqrt(xp * xp + yp * yp) / T(rho_scale);
    T zp = pol[0], power = rho;
    for (int i = 1; i < kOCamMaxDegree; ++i) power *= rho, zp += pol[i] * power;
    zp *= T(rho_scale);
    const T norm = sqrt(xp * xp + yp * yp + zp * zp);
    T target[3];
    ToCentral(OCamFlip(), tilt, offset, target);
    const T target_norm = sqrt(target[0] * target[0] + target[1] * target[1] + target[2] * target[2]);
    residual[0] = T(px_per_rad) * (xp / norm - target[0] / target_norm);
    residual[1] = T(px_per_rad) * (yp / norm - target[1] / target_norm);
    residual[2] = T(px_per_rad) * (zp / norm - target[2] / target_norm);
    return true;
  }
};

void Solve(ceres::Problem* problem) {
  ceres::Solver::Options options;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.logging_type = ceres::SILENT;  // a library never prints
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
}

void RequireSamples(const CentralFitSamples& samples) {
  if (samples.pixels.size() < 50)
    throw std::runtime_error("only " + std::to_string(samples.pixels.size()) + " field samples: too few for a central fit");
}

// world2cam's inverse polynomial rho(theta), theta = atan(z / |xy|): fitted to the forward
// model over the field's radii, the degree raised until it holds to 0.01 px.
void FitInversePolynomial(OCamModel* model, double rho_max) {
  std::vector<double> thetas, rhos;
  for (int k = 1; k <= 2000; ++k) {
    const double rho = 1.05 * rho_max * k / 2000.0;
    double z = 0.0, power = 1.0;
    for (double coefficient : model->pol) z += coefficient * power, power *= rho;
    thetas.push_back(std::atan(z / rho));
    rhos.push_back(rho);
  }
  for (int degree = 3; degree <= 24; ++degree) {
    Eigen::MatrixXd v(thetas.size(), degree + 1);
    Eigen::VectorXd r(thetas.size());
    for (size_t i = 0; i < thetas.size(); ++i) {
      double power = 1.0;
      for (int j = 0; j <= degree; ++j) v(i, j) = power, power *= thetas[i];
      r(i) = rhos[i];
    }
    const Eigen::VectorXd coefficients = v.colPivHouseholderQr().solve(r);
    model->invpol.assign(coefficients.data(), coefficients.data() + coefficients.size());
    if ((v * coefficients - r).cwiseAbs().maxCoeff() < 0.01) break;
  }
}

}  // namespace

CentralFitSamples SampleField(const Sensor& sensor, const ObjectSurface& surface, double v0_mm, double step_px) {
  CentralFitSamples samples;
  const Eigen::Matrix3d& rotation = sensor.cache().camera_from_mirror_rotation;
  const Eigen::Vector3d& translation = sensor.cache().camera_from_mirror_translation;
  const Eigen::Vector3d v0(0.0, 0.0, v0_mm);
  for (double v = 0.5 * step_px; v < sensor.image_height_px(); v += step_px)
    for (double u = 0.5 * step_px; u < sensor.image_width_px(); u += step_px) {
      Eigen::Vector3d origin, direction, point;
      if (sensor.Unproject(Eigen::Vector2d(u, v), &origin, &direction) != ProjectionStatus::kOk) continue;
      const Eigen::Vector3d origin_m = rotation.transpose() * (origin - translation);
      const Eigen::Vector3d direction_m = rotation.transpose() * direction;
      if (!surface.IntersectRay(v0, origin_m, direction_m, InfinityDistanceMm(sensor), &point)) continue;
      samples.pixels.emplace_back(u, v);
      samples.points_in_mirror.push_back(point);
      samples.omega_deg.push_back(std::acos(std::clamp(-direction_m.z(), -1.0, 1.0)) * 180.0 / M_PI);
    }
  return samples;
}

bool MeiModel::Project(const Eigen::Vector3d& point_in_mirror, Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d point = central_from_mirror * (point_in_mirror - Eigen::Vector3d(0.0, 0.0, v0_mm));
  const double intrinsics[10] = {fx, fy, cx, cy, skew, xi, k1, k2, p1, p2};
  double out[2];
  if (!MeiProject(intrinsics, point.data(), out)) return false;
  *pixel << out[0], out[1];
  return true;
}

MeiModel FitMei(const CentralFitSamples& samples, double v0_mm) {
  RequireSamples(samples);
  const Eigen::Vector3d v0(0.0, 0.0, v0_mm);
  // Start: xi = 1 (a paraboloid's model), the field's mean pixel as the centre, the focal
  // length from the median ratio of image radius to the model's normalised radius.
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : samples.pixels) centre += p;
  centre /= samples.pixels.size();
  std::vector<double> ratios;
  for (size_t i = 0; i < samples.pixels.size(); ++i) {
    const Eigen::Vector3d x = MeiFlip() * (samples.points_in_mirror[i] - v0).normalized();
    const double radius = std::hypot(x.x(), x.y()) / (x.z() + 1.0);
    if (radius > 0.05 && std::isfinite(radius)) ratios.push_back((samples.pixels[i] - centre).norm() / radius);
  }
  if (ratios.empty()) throw std::runtime_error("no field sample off the axis: cannot start a central fit");
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  const double focal = ratios[ratios.size() / 2];
  double intrinsics[10] = {focal, focal, centre.x(), centre.y(), 0.0, 1.0, 0.0, 0.0, 0.0, 0.0};
  double tilt[2] = {0.0, 0.0};
  ceres::Problem problem;
  for (size_t i = 0; i < samples.pixels.size(); ++i)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<MeiResidual, 2, 10, 2>(
                                 new MeiResidual{samples.points_in_mirror[i] - v0, samples.pixels[i]}),
                             nullptr, intrinsics, tilt);
  Solve(&problem);
  MeiModel model;
  model.fx = intrinsics[0], model.fy = intrinsics[1], model.cx = intrinsics[2], model.cy = intrinsics[3];
  model.skew = intrinsics[4], model.xi = intrinsics[5];
  model.k1 = intrinsics[6], model.k2 = intrinsics[7], model.p1 = intrinsics[8], model.p2 = intrinsics[9];
  model.central_from_mirror = CentralFromMirror(MeiFlip(), tilt);
  model.v0_mm = v0_mm;
  return model;
}

bool OCamModel::Project(const Eigen::Vector3d& point_in_mirror, Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d p = central_from_mirror * (point_in_mirror - Eigen::Vector3d(0.0, 0.0, v0_mm));
  const double norm = std::hypot(p.x(), p.y());
  if (norm == 0.0) {
    *pixel << yc_col, xc_row;
    return true;
  }
  const double theta = std::atan(p.z() / norm);
  double rho = 0.0, power = 1.0;
  for (double coefficient : invpol) rho += coefficient * power, power *= theta;
  const double x = p.x() / norm * rho, y = p.y() / norm * rho;
  *pixel << x * e + y + yc_col, x * c + y * d + xc_row;
  return true;
}

OCamModel FitOCam(const Sensor& sensor, const CentralFitSamples& samples, double v0_mm) {
  RequireSamples(samples);
  const Eigen::Vector3d v0(0.0, 0.0, v0_mm);
  // Start from the Mei fit's centre and local scale (the weight that turns a direction
  // error into px).
  const MeiModel mei = FitMei(samples, v0_mm);
  const double start_centre[5] = {mei.cy, mei.cx, 1.0, 0.0, 0.0};
  std::vector<double> px_per_rad(samples.pixels.size());
  double rho_scale = 0.0;
  for (size_t i = 0; i < samples.pixels.size(); ++i) {
    const Eigen::Vector3d offset = samples.points_in_mirror[i] - v0;
    const Eigen::Vector3d side = offset.cross(Eigen::Vector3d::UnitZ()).norm() > 1e-9 * offset.norm()
                                     ? offset.cross(Eigen::Vector3d::UnitZ()).normalized()
                                     : Eigen::Vector3d::UnitX();
    Eigen::Vector2d p0, p1;
    mei.Project(v0 + offset, &p0);
    mei.Project(v0 + offset + 1e-4 * offset.norm() * offset.normalized().cross(side), &p1);
    px_per_rad[i] = (p1 - p0).norm() / 1e-4;
    rho_scale = std::max(rho_scale, std::hypot(samples.pixels[i].y() - start_centre[0], samples.pixels[i].x() - start_centre[1]));
  }
  // The polynomial's degree: OCamCalib's default is 4, which leaves pixels of error on a
  // wide-field sphere; raised until the worst sample is within 0.05 px (or 13).
  OCamModel best;
  double best_max = HUGE_VAL;
  for (int degree = 4; degree <= kOCamMaxDegree; ++degree) {
    double centre[5];
    std::copy(start_centre, start_centre + 5, centre);
    // a0, a2..a_degree linear given the centre: (xp, yp, z) is parallel to the sample's
    // direction t when z = rho t_z / |t_xy|.
    Eigen::MatrixXd a(samples.pixels.size(), degree);
    Eigen::VectorXd b(samples.pixels.size());
    for (size_t i = 0; i < samples.pixels.size(); ++i) {
      const Eigen::Vector3d t = OCamFlip() * (samples.points_in_mirror[i] - v0);
      const double rho = std::hypot(samples.pixels[i].y() - centre[0], samples.pixels[i].x() - centre[1]) / rho_scale;
      a(i, 0) = 1.0;
      for (int j = 1; j < degree; ++j) a(i, j) = std::pow(rho, j + 1);
      b(i) = rho * t.z() / std::max(1e-12, std::hypot(t.x(), t.y()));
    }
    const Eigen::VectorXd start = a.colPivHouseholderQr().solve(b);
    double pol[kOCamMaxDegree] = {};
    for (int j = 0; j < degree; ++j) pol[j] = start(j);
    double tilt[2] = {0.0, 0.0};
    ceres::Problem problem;
    for (size_t i = 0; i < samples.pixels.size(); ++i)
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<OCamResidual, 3, 5, kOCamMaxDegree, 2>(new OCamResidual{
                                   samples.points_in_mirror[i] - v0, samples.pixels[i], px_per_rad[i], rho_scale}),
                               nullptr, centre, pol, tilt);
    if (degree < kOCamMaxDegree) {
      std::vector<int> unused;
      for (int j = degree; j < kOCamMaxDegree; ++j) unused.push_back(j);
      problem.SetManifold(pol, new ceres::SubsetManifold(kOCamMaxDegree, unused));
    }
    Solve(&problem);

    OCamModel model;
    model.xc_row = centre[0], model.yc_col = centre[1], model.c = centre[2], model.d = centre[3], model.e = centre[4];
    model.pol = {pol[0] * rho_scale, 0.0};
    for (int j = 1; j < degree; ++j) model.pol.push_back(pol[j] * rho_scale / std::pow(rho_scale, j + 1));
    model.height = sensor.image_height_px(), model.width = sensor.image_width_px();
    model.central_from_mirror = CentralFromMirror(OCamFlip(), tilt);
    model.v0_mm = v0_mm;
    FitInversePolynomial(&model, rho_scale);
    const double max_px = ErrorOf(model, samples).max_px;
    if (max_px < best_max) best = model, best_max = max_px;
    if (best_max < 0.05) break;
  }
  return best;
}

}  // namespace omnical
