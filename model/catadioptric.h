// A catadioptric sensor: a lens looking at a rotationally symmetric mirror in a given
// pose, with exact projection (point -> pixel) and unprojection (pixel -> ray).
//
// Composed at compile time from a profile and a lens (model/mirror_profiles.h,
// model/lenses.h), templated on the scalar T so ceres::Jet flows through Project().
// Solvers run in double; a Jet model then takes one Newton step in T from the double
// root, which gives exactly the implicit-function-theorem derivative
// (NONCENTRAL-NOTES; Ceres inverse_and_implicit_function_theorems).
//
// Valid domain: a point is imaged when its reflection point lies on the mirror
// (radius <= rim_radius_mm), on the reflecting side, the ray from the mirror to it does
// not hit the camera body, and the pixel is inside the image. Anything else returns a
// ProjectionStatus; nothing throws.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "model/axial_reflection.h"
#include "model/fermat_reflection.h"
#include "model/guess_table.h"
#include "model/lenses.h"
#include "model/mirror_pose.h"
#include "model/mirror_profiles.h"
#include "model/scalar.h"
#include "model/types.h"

namespace omnical {

// Double-only precomputation for projecting many points with one sensor: the pose
// rotation (trigonometry per point would cost as much as the solve) and the guess table.
struct ProjectionCache {
  Eigen::Matrix3d camera_from_mirror_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d camera_from_mirror_translation = Eigen::Vector3d::Zero();
  AxialGuessTable guess;

  // A camera-frame point (mm) in the mirror's frame (its axis z).
  Eigen::Vector3d InMirrorFrame(const Eigen::Vector3d& point_in_camera_mm) const {
    return camera_from_mirror_rotation.transpose() * (point_in_camera_mm - camera_from_mirror_translation);
  }
};

// A solved reflection point kept by a caller that projects the same point through the
// same model again: automatic derivatives evaluate a cost in several passes (8 derivatives
// each) with identical scalar parts, and a solver's plain residual comes before its
// Jacobian at the same parameters. Only the caller knows the inputs are unchanged, so it
// says so (reuse); the answer is then bit-identical to solving again, minus the solve.
struct SolvedReflection {
  Eigen::Vector2d q_mm = Eigen::Vector2d::Zero();  // the reflection point, mirror frame
  Eigen::Matrix2d fermat_jacobian = Eigen::Matrix2d::Zero();  // dF/dq at q_mm (the Jet step's)
  bool has_q = false, has_jacobian = false;
  bool reuse = false;  // set by the caller: same point, same model as the solve that filled it
};

template <typename T, template <typename> class Profile, template <typename> class Lens>
struct Catadioptric {
  using Scalar = T;
  using ProfileType = Profile<T>;
  using LensType = Lens<T>;
  template <typename U>
  using ProfileOf = Profile<U>;
  template <typename U>
  using LensOf = Lens<U>;
  static constexpr bool kOrthographic = Lens<T>::kIsOrthographic;

  Profile<T> mirror;
  Lens<T> lens;
  MirrorPose<T> pose;
  double rim_radius_mm = 0.0;
  int image_width_px = 0;
  int image_height_px = 0;
  // Radius of the camera body, a half-infinite cylinder around the optical axis behind
  // the lens plane (z <= 0 in the camera frame); 0 = no occlusion test.
  double camera_body_radius_mm = 0.0;

  // With no tilt and no decenter every ray lies in a plane through the axis. An
  // orthographic lens sees a decentred mirror along its axis too.
  bool IsAxial() const { return pose.IsUntilted() && (kOrthographic || pose.IsCentred()); }

  bool InImage(double u, double v) const {
    // '&': no branches, for the batch loops.
    return (u >= -0.5) & (u <= image_width_px - 0.5) & (v >= -0.5) & (v <= image_height_px - 0.5);
  }

  template <typename U>
  Catadioptric<U, Profile, Lens> Cast() const {
    Catadioptric<U, Profile, Lens> out;
    out.mirror = mirror.template Cast<U>();
    out.lens = lens.template Cast<U>();
    out.pose = pose.template Cast<U>();
    out.rim_radius_mm = rim_radius_mm;
    out.image_width_px = image_width_px;
    out.image_height_px = image_height_px;
    out.camera_body_radius_mm = camera_body_radius_mm;
    return out;
  }

  ProjectionCache MakeCache() const {
    ProjectionCache cache;
    const Catadioptric<double, Profile, Lens> model = Cast<double>();
    cache.camera_from_mirror_rotation = model.pose.CameraFromMirrorRotation();
    cache.camera_from_mirror_translation = model.pose.CameraFromMirrorTranslation();
    cache.guess = AxialGuessTable(kOrthographic, model.pose.m_mm, model.mirror, rim_radius_mm);
    return cache;
  }

  // Reflection point on the mirror (camera frame, mm) of the ray that images the point.
  // solved (optional): filled with the solve's root; with solved->reuse, that root is
  // taken instead of solving.
  ProjectionStatus ReflectionPoint(const Vec3<T>& point_in_camera, Vec3<T>* mirror_point_in_camera,
                                   const ProjectionCache* cache = nullptr, SolvedReflection* solved = nullptr) const;

  // Pixel of a point given in the camera frame (mm).
  ProjectionStatus Project(const Vec3<T>& point_in_camera, Vec2<T>* pixel,
                           const ProjectionCache* cache = nullptr) const {
    Vec3<T> mirror_point;
    const ProjectionStatus status = ReflectionPoint(point_in_camera, &mirror_point, cache);
    if (status != ProjectionStatus::kOk) return status;
    if (!lens.ProjectToPixel(mirror_point, pixel)) return ProjectionStatus::kNoSolution;
    if (!InImage(ScalarPart((*pixel)(0)), ScalarPart((*pixel)(1)))) return ProjectionStatus::kOutsideImage;
    return ProjectionStatus::kOk;
  }

  // World ray of a pixel, in the camera frame: origin on the mirror surface (mm) and
  // unit direction towards the scene.
  ProjectionStatus Unproject(const Vec2<T>& pixel, Vec3<T>* origin_in_camera, Vec3<T>* direction_in_camera,
                             const ProjectionCache* cache = nullptr) const;
};

namespace detail {

// The rim itself belongs to the mirror: without a little slack the ray of the exact rim
// pixel would be rejected by a rounding error.
constexpr double kRimSlack = 1.0 + 1e-12;

// Newton steps below this are accepted (the step itself is applied). Quadratic
// convergence leaves an error ~ step^2 / L, where L is the length over which the
// residual bends: the rim radius, or the distance to the point when that is smaller
// (points very near the mirror). So the remaining error is ~1e-14 L.
inline double AcceptStep(double rim_mm, double point_distance_mm) {
  return 1e-7 * std::min(rim_mm, point_distance_mm);
}

// Beyond this a coordinate's square overflows or the point is numerically at infinity.
constexpr double kMaxCoordinateMm = 1e30;

inline bool AllFinite(double a, double b, double c = 0.0) {
  return std::isfinite(a) && std::isfinite(b) && std::isfinite(c);
}

// Whether the segment from a mirror point to a scene point (camera frame) passes
// through the camera body (see camera_body_radius_mm).
inline bool HitsCameraBody(const Eigen::Vector3d& mirror_point, const Eigen::Vector3d& point,
                           double body_radius_mm) {
  if (!(body_radius_mm > 0.0) || point.z() >= 0.0) return false;
  const double r2 = body_radius_mm * body_radius_mm;
  if (point.head<2>().squaredNorm() < r2) return true;
  const double t = mirror_point.z() / (mirror_point.z() - point.z());
  return (mirror_point.head<2>() + t * (point - mirror_point).head<2>()).squaredNorm() < r2;
}

// Reflection radius x of an axial sensor for a point at radius rho, height h (mirror
// frame): safeguarded Newton on G (axial_reflection.h), bracket [lo, hi] kept with
// G(lo) > 0 > G(hi), bisection when a step leaves it. The rim is only evaluated when the
// fast path fails, so a good guess costs 2-3 evaluations.
template <typename Profile>
ProjectionStatus SolveAxialRadius(bool orthographic, double m_mm, const Profile& mirror, double rim_mm,
                                  double rho, double h, const AxialGuessTable* guess, double* x_out,
                                  double* dg_dx_out) {
  const double bisect_tolerance = 1e-13 * rim_mm;  // only reached if Newton keeps failing
  double lo = 0.0, hi = rim_mm;
  bool rim_checked = false;
  auto check_rim = [&]() {
    rim_checked = true;
    const AxialReflection at_rim =
        EvaluateAxialReflection(orthographic, m_mm, rim_mm, mirror.EvaluateSag(rim_mm * rim_mm), rho, h);
    return at_rim.g < 0.0;
  };
  double x;
  if (guess != nullptr && guess->valid()) {
    x = std::min(guess->Guess(rho, h), rim_mm);
  } else {
    if (!check_rim()) return ProjectionStatus::kOutsideMirror;
    x = 0.5 * rim_mm;
  }
  for (int iteration = 0; iteration < 200; ++iteration) {
    const AxialReflection r =
        EvaluateAxialReflection(orthographic, m_mm, x, mirror.EvaluateSag(x * x), rho, h);
    if (r.g > 0.0) {
      lo = x;
    } else {
      hi = x;
      rim_checked = true;  // a point with G <= 0 inside [0, rim] is a valid upper bracket
    }
    double x_next = x - r.g / r.dg_dx;
    // A small Newton step is accepted before the bracket test: at the root the bracket
    // collapses onto x and a step of one rounding error would fail it.
    const double distance = std::sqrt((rho - x) * (rho - x) + (h - r.sag_mm) * (h - r.sag_mm));
    const bool newton_converged = std::abs(x_next - x) < AcceptStep(rim_mm, distance);
    if (!newton_converged && !(x_next > lo && x_next < hi)) {
      if (!rim_checked && !check_rim()) return ProjectionStatus::kOutsideMirror;
      x_next = 0.5 * (lo + hi);
    }
    if (newton_converged || hi - lo < bisect_tolerance) {
      *x_out = x_next;
      *dg_dx_out = r.dg_dx;
      // Forward condition: the point lies ahead on the reflected ray.
      if (!(r.r_x * (rho - x) + r.r_z * (h - r.sag_mm) > 0.0)) return ProjectionStatus::kBehindMirror;
      if (x_next > rim_mm * kRimSlack) return ProjectionStatus::kOutsideMirror;
      return ProjectionStatus::kOk;
    }
    x = x_next;
  }
  return ProjectionStatus::kNoSolution;
}

// Reflection point (x, y) of a tilted/decentred sensor: damped Newton on the Fermat
// condition (fermat_reflection.h) with backtracking on the path length, seeded by the
// axial guess along the point's azimuth.
template <bool kOrtho, typename Profile>
ProjectionStatus SolveFermatPoint(const Eigen::Vector3d& lens, const Profile& mirror, double rim_mm,
                                  const Eigen::Vector3d& point, double seed_radius, Eigen::Vector2d* q_out,
                                  Eigen::Matrix2d* jacobian_out) {
  // Iterates may pass the rim a little (points just outside the field converge there),
  // but not far: beyond it a profile is only an extrapolation.
  const double max_radius = std::min(1.2 * rim_mm, (1.0 - 1e-9) * mirror.MaxRadiusMm());
  const double rho = point.head<2>().norm();
  auto evaluate = [&](const Eigen::Vector2d& q) {
    return EvaluateFermatReflection<kOrtho>(lens.x(), lens.y(), lens.z(), mirror, point.x(), point.y(), point.z(),
                                            q.x(), q.y());
  };
  Eigen::Vector2d q = seed_radius / rho * point.head<2>();
  FermatReflection e = evaluate(q);
  // Iterations in a row that moved outwards and ended outside the mirror with their full
  // step cut short at max_radius: the root lies beyond the mirror, and the iterates would
  // only creep towards that wall for the remaining iterations, halving each step (most of
  // a detection's time through a tilted tabulated mirror went into such points at the
  // edges of its views).
  int pressed_to_wall = 0;
  for (int iteration = 0; iteration < 100; ++iteration) {
    Eigen::Vector2d step;
    if (!FermatNewtonStep(e, &step.x(), &step.y())) {
      // Near a caustic: a bounded step down the gradient of L (which is -F).
      const double norm = std::hypot(e.f_x, e.f_y);
      if (!(norm > 0.0)) return ProjectionStatus::kNoSolution;
      step = Eigen::Vector2d(e.f_x, e.f_y) * (0.05 * rim_mm / norm);
    }
    const double distance = (point - Eigen::Vector3d(q.x(), q.y(), e.z)).norm();
    if (step.norm() < AcceptStep(rim_mm, distance)) {
      *q_out = q + step;
      *jacobian_out << e.j_xx, e.j_xy, e.j_xy, e.j_yy;
      const Eigen::Vector3d to_point = point - Eigen::Vector3d(q.x(), q.y(), e.z);
      if (!(to_point.dot(Eigen::Vector3d(e.slope_x, e.slope_y, -1.0)) > 0.0)) return ProjectionStatus::kBehindMirror;
      if (q_out->norm() > rim_mm * kRimSlack) return ProjectionStatus::kOutsideMirror;
      return ProjectionStatus::kOk;
    }
    const double radius_before = q.norm();
    double alpha = 1.0;
    bool cut_at_wall = false;
    for (int halving = 0;; ++halving) {
      const Eigen::Vector2d trial = q + alpha * step;
      if (trial.norm() < max_radius) {
        const FermatReflection t = evaluate(trial);
        if (t.path_length <= e.path_length + 1e-12 * std::abs(e.path_length) || halving >= 30) {
          q = trial;
          e = t;
          break;
        }
      } else if (halving >= 30) {
        return ProjectionStatus::kOutsideMirror;
      } else {
        cut_at_wall = true;
      }
      alpha *= 0.5;
    }
    // Only outward moves count: a near-singular step may cross the disc and cut the far
    // wall on its way back inside.
    const double radius_after = q.norm();
    pressed_to_wall =
        cut_at_wall && radius_after > radius_before && radius_after > rim_mm * kRimSlack ? pressed_to_wall + 1 : 0;
    if (pressed_to_wall >= 3) return ProjectionStatus::kOutsideMirror;
  }
  return ProjectionStatus::kNoSolution;
}

// Where the lens ray o + t d (mirror frame, d unit) meets the mirror, within the
// cylinder r <= rim: safeguarded Newton on g(t) = o_z + t d_z - f(|o_xy + t d_xy|^2)
// with the bracket [cylinder entry, cylinder exit].
template <typename Profile>
ProjectionStatus SolveRayHit(const Profile& mirror, double rim_mm, const Eigen::Vector3d& o,
                             const Eigen::Vector3d& d, double* t_out, double* dg_dt_out) {
  auto g_and_slope = [&](double t, double* slope) {
    const double px = o.x() + t * d.x(), py = o.y() + t * d.y();
    const SagDerivatives<double> sag = mirror.EvaluateSag(px * px + py * py);
    *slope = d.z() - sag.dz_ds * 2.0 * (px * d.x() + py * d.y());
    return o.z() + t * d.z() - sag.z;
  };
  const double a = d.x() * d.x() + d.y() * d.y();
  const double b = o.x() * d.x() + o.y() * d.y();
  const double c = o.x() * o.x() + o.y() * o.y() - rim_mm * rim_mm * (kRimSlack * kRimSlack);
  if (a < 1e-24) {  // parallel to the axis (orthographic lens, or the central pixel)
    if (!(d.z() > 0.0)) return ProjectionStatus::kMissesMirror;
    if (c > 0.0) return ProjectionStatus::kOutsideMirror;
    *t_out = (mirror.EvaluateSag(o.x() * o.x() + o.y() * o.y()).z - o.z()) / d.z();
    *dg_dt_out = d.z();
    return ProjectionStatus::kOk;
  }
  const double disc = b * b - a * c;
  if (disc < 0.0) return ProjectionStatus::kOutsideMirror;
  const double root = std::sqrt(disc);
  const double t_exit = (-b + root) / a;
  if (!(t_exit > 0.0)) return ProjectionStatus::kOutsideMirror;  // passes beside the mirror
  double lo = std::max(0.0, (-b - root) / a), hi = t_exit;
  double slope = 0.0;
  if (g_and_slope(lo, &slope) >= 0.0) return lo > 0.0 ? ProjectionStatus::kOutsideMirror : ProjectionStatus::kMissesMirror;
  if (g_and_slope(hi, &slope) < 0.0) return ProjectionStatus::kOutsideMirror;
  // Start where the ray crosses the vertex plane when that is inside the bracket.
  double t = (d.z() > 0.0) ? std::clamp(-o.z() / d.z(), lo, hi) : lo;
  const double accept_step = 1e-7 * rim_mm;  // quadratic convergence: next error ~1e-14 rim
  const double bisect_tolerance = 1e-13 * rim_mm;
  for (int iteration = 0; iteration < 200; ++iteration) {
    const double g = g_and_slope(t, &slope);
    if (g < 0.0) lo = t; else hi = t;
    double t_next = t - g / slope;
    const bool newton_converged = std::abs(t_next - t) < accept_step;
    if (!newton_converged && !(t_next > lo && t_next < hi)) t_next = 0.5 * (lo + hi);
    if (newton_converged || hi - lo < bisect_tolerance) {
      *t_out = t_next;
      *dg_dt_out = slope;
      return ProjectionStatus::kOk;
    }
    t = t_next;
  }
  return ProjectionStatus::kNoSolution;
}

template <typename T>
Vec3<T> ToT(const Eigen::Vector3d& v) {
  return Vec3<T>(T(v.x()), T(v.y()), T(v.z()));
}
template <typename T>
Eigen::Vector3d ToDouble(const Vec3<T>& v) {
  return Eigen::Vector3d(ScalarPart(v.x()), ScalarPart(v.y()), ScalarPart(v.z()));
}

template <typename T, template <typename> class Profile, template <typename> class Lens>
ProjectionStatus ReflectionPointImpl(const Catadioptric<T, Profile, Lens>& model,
                                     const Catadioptric<double, Profile, Lens>& model_d,
                                     const Vec3<T>& point_in_camera, Vec3<T>* mirror_point_in_camera,
                                     const ProjectionCache* cache, SolvedReflection* solved) {
  constexpr bool kJet = !std::is_same_v<T, double>;
  constexpr bool kOrtho = Lens<T>::kIsOrthographic;
  const bool reuse = solved != nullptr && solved->reuse && solved->has_q;
  if (solved != nullptr && !reuse) *solved = SolvedReflection{};  // filled again only by a solve that succeeds
  const Eigen::Vector3d point_d = ToDouble(point_in_camera);
  if (!AllFinite(point_d.x(), point_d.y(), point_d.z()) || point_d.cwiseAbs().maxCoeff() > kMaxCoordinateMm)
    return ProjectionStatus::kInvalidInput;
  const double rim = model.rim_radius_mm;
  const AxialGuessTable* guess = cache != nullptr ? &cache->guess : nullptr;
  const Eigen::Vector3d translation_d = model_d.pose.CameraFromMirrorTranslation();
  const bool axial = model_d.IsAxial();
  // Untilted means the rotation is exactly the identity: skip the trigonometry.
  const Eigen::Matrix3d rotation_d = model_d.pose.IsUntilted() ? Eigen::Matrix3d::Identity()
                                     : cache != nullptr       ? cache->camera_from_mirror_rotation
                                                              : model_d.pose.CameraFromMirrorRotation();
  // 1. The reflection point q = (x, y) in the mirror frame, solved in double.
  const Eigen::Vector3d p = axial ? Eigen::Vector3d(point_d - translation_d)
                                  : Eigen::Vector3d(rotation_d.transpose() * (point_d - translation_d));
  const double rho = std::sqrt(p.x() * p.x() + p.y() * p.y());  // hypot's overflow care costs 2x here
  if (!(rho > 1e-12 * rim)) {
    // On the axis: only the vertex reflects it, straight back towards the camera.
    return p.z() < 0.0 ? ProjectionStatus::kOccludedByCamera : ProjectionStatus::kBehindMirror;
  }
  // The lens in the mirror frame: its centre, or for an orthographic lens the unit
  // direction from the mirror towards it.
  const Eigen::Vector3d lens_d = kOrtho ? Eigen::Vector3d(-rotation_d.row(2).transpose())
                                        : Eigen::Vector3d(-(rotation_d.transpose() * translation_d));
  Eigen::Vector2d q;
  Eigen::Matrix2d jacobian;
  if (reuse) {
    q = solved->q_mm;
  } else if (axial) {
    double x = 0.0, dg_dx = 0.0;
    const ProjectionStatus status =
        SolveAxialRadius(kOrtho, model_d.pose.m_mm, model_d.mirror, rim, rho, p.z(), guess, &x, &dg_dx);
    if (status != ProjectionStatus::kOk) return status;
    q = (x / rho) * p.head<2>();
  } else {
    const double seed = (guess != nullptr && guess->valid()) ? std::min(guess->Guess(rho, p.z()), rim) : 0.5 * rim;
    const ProjectionStatus status = SolveFermatPoint<kOrtho>(lens_d, model_d.mirror, rim, p, seed, &q, &jacobian);
    if (status != ProjectionStatus::kOk) return status;
  }
  if (solved != nullptr && !reuse) *solved = SolvedReflection{q, Eigen::Matrix2d::Zero(), true, false, false};
  // 2. The mirror point in the camera frame. Jets always take the general 2-D
  // implicit-function step, so tilt and decenter get their derivatives even at 0.
  if constexpr (kJet) {
    // The Jacobian at the root itself (the solvers' last one is one step before it).
    if (reuse && solved->has_jacobian) {
      jacobian = solved->fermat_jacobian;
    } else {
      const FermatReflection at_root = EvaluateFermatReflection<kOrtho>(
          lens_d.x(), lens_d.y(), lens_d.z(), model_d.mirror, p.x(), p.y(), p.z(), q.x(), q.y());
      jacobian << at_root.j_xx, at_root.j_xy, at_root.j_xy, at_root.j_yy;
      if (solved != nullptr) solved->fermat_jacobian = jacobian, solved->has_jacobian = true;
    }
    const Mat3<T> rotation = model.pose.CameraFromMirrorRotation();
    const Vec3<T> translation = model.pose.CameraFromMirrorTranslation();
    const Vec3<T> point_in_mirror = rotation.transpose() * (point_in_camera - translation);
    const Vec3<T> lens = kOrtho ? Vec3<T>(-rotation.row(2).transpose()) : Vec3<T>(-(rotation.transpose() * translation));
    const Vec2<T> f = FermatResidual<kOrtho>(lens, model.mirror, point_in_mirror, T(q.x()), T(q.y()));
    const Eigen::Matrix2d inverse = jacobian.inverse();
    const T qx = T(q.x()) - (T(inverse(0, 0)) * f(0) + T(inverse(0, 1)) * f(1));
    const T qy = T(q.y()) - (T(inverse(1, 0)) * f(0) + T(inverse(1, 1)) * f(1));
    const Vec3<T> mirror_point(qx, qy, model.mirror.EvaluateSag(qx * qx + qy * qy).z);
    *mirror_point_in_camera = rotation * mirror_point + translation;
  } else {
    const Eigen::Vector3d mirror_point(q.x(), q.y(), model.mirror.EvaluateSag(q.squaredNorm()).z);
    *mirror_point_in_camera = axial ? Eigen::Vector3d(mirror_point + translation_d)
                                    : Eigen::Vector3d(rotation_d * mirror_point + translation_d);
  }
  if (HitsCameraBody(ToDouble(*mirror_point_in_camera), point_d, model.camera_body_radius_mm))
    return ProjectionStatus::kOccludedByCamera;
  return ProjectionStatus::kOk;
}

template <typename T, template <typename> class Profile, template <typename> class Lens>
ProjectionStatus UnprojectImpl(const Catadioptric<T, Profile, Lens>& model,
                               const Catadioptric<double, Profile, Lens>& model_d, const Vec2<T>& pixel,
                               Vec3<T>* origin_in_camera, Vec3<T>* direction_in_camera,
                               const ProjectionCache* cache) {
  constexpr bool kJet = !std::is_same_v<T, double>;
  const double u = ScalarPart(pixel(0)), v = ScalarPart(pixel(1));
  if (!AllFinite(u, v)) return ProjectionStatus::kInvalidInput;
  if (!model.InImage(u, v)) return ProjectionStatus::kOutsideImage;
  Vec3<T> lens_origin, lens_direction;
  model.lens.PixelToRay(pixel, &lens_origin, &lens_direction);
  Mat3<T> rotation;
  if constexpr (kJet) {
    rotation = model.pose.CameraFromMirrorRotation();
  } else {
    rotation = cache != nullptr ? cache->camera_from_mirror_rotation : model.pose.CameraFromMirrorRotation();
  }
  const Vec3<T> translation = model.pose.CameraFromMirrorTranslation();
  const Vec3<T> o = rotation.transpose() * (lens_origin - translation);
  const Vec3<T> d = rotation.transpose() * lens_direction;
  double t_hit = 0.0, dg_dt = 0.0;
  const ProjectionStatus status =
      SolveRayHit(model_d.mirror, model.rim_radius_mm, ToDouble(o), ToDouble(d), &t_hit, &dg_dt);
  if (status != ProjectionStatus::kOk) return status;
  T t(t_hit);
  if constexpr (kJet) {
    const T px = o.x() + t * d.x(), py = o.y() + t * d.y();
    t -= (o.z() + t * d.z() - model.mirror.EvaluateSag(px * px + py * py).z) / dg_dt;
  }
  const Vec3<T> hit = o + t * d;
  const SagDerivatives<T> sag = model.mirror.EvaluateSag(hit.x() * hit.x() + hit.y() * hit.y());
  const Vec3<T> normal = Vec3<T>(T(2.0) * hit.x() * sag.dz_ds, T(2.0) * hit.y() * sag.dz_ds, T(-1.0)).normalized();
  const Vec3<T> reflected = d - T(2.0) * d.dot(normal) * normal;
  *origin_in_camera = rotation * hit + translation;
  *direction_in_camera = rotation * reflected;
  // The pixel sees the camera's own reflection when the reflected ray hits its body.
  const Eigen::Vector3d origin_d = ToDouble(*origin_in_camera), dir_d = ToDouble(*direction_in_camera);
  if (model.camera_body_radius_mm > 0.0 && dir_d.z() < 0.0) {
    const Eigen::Vector3d at_lens_plane = origin_d - origin_d.z() / dir_d.z() * dir_d;
    if (at_lens_plane.head<2>().norm() < model.camera_body_radius_mm) return ProjectionStatus::kOccludedByCamera;
  }
  return ProjectionStatus::kOk;
}

}  // namespace detail

template <typename T, template <typename> class Profile, template <typename> class Lens>
ProjectionStatus Catadioptric<T, Profile, Lens>::ReflectionPoint(const Vec3<T>& point_in_camera,
                                                                 Vec3<T>* mirror_point_in_camera,
                                                                 const ProjectionCache* cache,
                                                                 SolvedReflection* solved) const {
  if constexpr (std::is_same_v<T, double>) {
    return detail::ReflectionPointImpl(*this, *this, point_in_camera, mirror_point_in_camera, cache, solved);
  } else {
    return detail::ReflectionPointImpl(*this, Cast<double>(), point_in_camera, mirror_point_in_camera, cache, solved);
  }
}

template <typename T, template <typename> class Profile, template <typename> class Lens>
ProjectionStatus Catadioptric<T, Profile, Lens>::Unproject(const Vec2<T>& pixel, Vec3<T>* origin_in_camera,
                                                           Vec3<T>* direction_in_camera,
                                                           const ProjectionCache* cache) const {
  if constexpr (std::is_same_v<T, double>) {
    return detail::UnprojectImpl(*this, *this, pixel, origin_in_camera, direction_in_camera, cache);
  } else {
    return detail::UnprojectImpl(*this, Cast<double>(), pixel, origin_in_camera, direction_in_camera, cache);
  }
}

}  // namespace omnical
