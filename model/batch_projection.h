// Projection of many points with one sensor, in blocks laid out as structure of
// arrays so that every stage runs in a loop the compiler vectorises (and, through
// OMNICAL_CLONE_FOR_AVX2, with 4-wide AVX2 where the CPU has it).
//
// Each block takes the table guess, then a fixed number of plain Newton steps (3 for an
// axial sensor: guess error up to ~0.1 mm -> ~1e-4 -> ~1e-9 -> rounding; 3 for the 2-D
// Fermat solve, whose seed ignores the misalignment). A point is accepted only when its
// last step was below the scalar solver's acceptance threshold (detail::AcceptStep) and
// every validity check holds; any other point (a poor guess, a point outside the field,
// NaN) is projected again by the safeguarded scalar solver, which also supplies the
// failure status. The answers are those of Catadioptric::Project to its tolerance
// (~1e-10 px). With two axial steps one point in six missed the threshold and took the
// scalar path, which cost more than the third step does for all.
#pragma once

#include <algorithm>
#include <cmath>

#include "model/batch_sag.h"
#include "model/catadioptric.h"
#include "model/simd_clones.h"

namespace omnical {

template <typename Model>
OMNICAL_CLONE_FOR_AVX2 void ProjectPointsBatch(const Model& model, const ProjectionCache& cache,
                                               const double* points_xyz, long count, double* pixels_uv,
                                               ProjectionStatus* statuses) {
  constexpr bool kOrtho = Model::kOrthographic;
  constexpr int kBlock = 256;
  constexpr int kNewtonSteps = 3;
  const double rim = model.rim_radius_mm;
  const double max_radius = rim * detail::kRimSlack;
  const bool axial = model.IsAxial();
  const Eigen::Matrix3d& rotation = cache.camera_from_mirror_rotation;
  const Eigen::Vector3d translation = model.pose.CameraFromMirrorTranslation();
  const Eigen::Vector3d lens = kOrtho ? Eigen::Vector3d(-rotation.row(2).transpose())
                                      : Eigen::Vector3d(-(rotation.transpose() * translation));
  // Plain copies: the vector loops must not re-read them through a pointer the stores
  // might alias.
  const double t_x = translation.x(), t_y = translation.y(), t_z = translation.z();
  const double r00 = rotation(0, 0), r01 = rotation(0, 1), r02 = rotation(0, 2);
  const double r10 = rotation(1, 0), r11 = rotation(1, 1), r12 = rotation(1, 2);
  const double r20 = rotation(2, 0), r21 = rotation(2, 1), r22 = rotation(2, 2);
  const double lens_x = lens.x(), lens_y = lens.y(), lens_z = lens.z();
  const double m_mm = model.pose.m_mm;
  const double body_radius_mm = model.camera_body_radius_mm;
  const auto& mirror = BatchProfile(model.mirror);  // (a temporary for the polynomial, kept alive)

  alignas(64) double px[kBlock], py[kBlock], pz[kBlock], rho[kBlock];
  alignas(64) double qx[kBlock], qy[kBlock], last_step[kBlock], ahead[kBlock];
  alignas(64) double u[kBlock], v[kBlock], distance[kBlock], radius[kBlock];
  alignas(64) double mirror_x[kBlock], mirror_y[kBlock], mirror_z[kBlock];  // camera frame
  alignas(64) bool accepted[kBlock];
  for (long start = 0; start < count; start += kBlock) {
    const int n = static_cast<int>(std::min<long>(kBlock, count - start));
    const double* block = points_xyz + 3 * start;

    // 1. Mirror-frame coordinates (rotation^T (p - t); an axial sensor's rotation is the
    //    identity) and the table guess.
    for (int i = 0; i < n; ++i) {
      // A point with a NaN, infinite or huge coordinate fails the checks in step 4 and gets
      // its status from the scalar solver; the vector loops work on a harmless stand-in
      // instead, so that no profile sees a NaN (a spline's segment index would be one).
      const bool finite = std::max(std::max(std::abs(block[3 * i]), std::abs(block[3 * i + 1])),
                                   std::abs(block[3 * i + 2])) <= detail::kMaxCoordinateMm;
      const double x = (finite ? block[3 * i] : 10.0 * rim) - t_x, y = (finite ? block[3 * i + 1] : 0.0) - t_y,
                   z = (finite ? block[3 * i + 2] : 0.0) - t_z;
      px[i] = r00 * x + r10 * y + r20 * z;
      py[i] = r01 * x + r11 * y + r21 * z;
      pz[i] = r02 * x + r12 * y + r22 * z;
      rho[i] = std::sqrt(px[i] * px[i] + py[i] * py[i]);
    }
    if (cache.guess.valid()) {
      cache.guess.GuessMany(rho, pz, n, qx);
    } else {
      std::fill(qx, qx + n, 0.5 * rim);
    }

    if (axial) {
      // 2. Fixed Newton steps on G(x); the last also gives the forward condition at the
      //    point it stepped from, as the scalar solver tests it.
      for (int pass = 0; pass < kNewtonSteps; ++pass) {
        for (int i = 0; i < n; ++i) {
          const double x = qx[i];
          const AxialReflection r = EvaluateAxialReflection(kOrtho, m_mm, x, mirror.EvaluateSag(x * x), rho[i], pz[i]);
          const double step = r.g / r.dg_dx;
          qx[i] = x - step;
          last_step[i] = std::abs(step);
          ahead[i] = r.r_x * (rho[i] - x) + r.r_z * (pz[i] - r.sag_mm);
        }
      }
      // 3. The mirror point and its pixel.
      for (int i = 0; i < n; ++i) {
        const double x = qx[i], scale = x / rho[i];
        const double sag_mm = mirror.EvaluateSag(x * x).z;
        const Vec3<double> mirror_point(px[i] * scale + t_x, py[i] * scale + t_y, sag_mm + t_z);
        Vec2<double> pixel;
        const bool in_front = model.lens.ProjectToPixel(mirror_point, &pixel);
        // NaN fails InImage below. (Selecting the pixel itself would keep the loop scalar.)
        u[i] = pixel.x() + (in_front ? 0.0 : NAN);
        v[i] = pixel.y() + (in_front ? 0.0 : NAN);
        mirror_x[i] = mirror_point.x(), mirror_y[i] = mirror_point.y(), mirror_z[i] = mirror_point.z();
        distance[i] = std::sqrt((rho[i] - x) * (rho[i] - x) + (pz[i] - sag_mm) * (pz[i] - sag_mm));
        radius[i] = x;
      }
    } else {
      // 2. The seed on the point's azimuth, then fixed Newton steps on the Fermat
      //    condition.
      for (int i = 0; i < n; ++i) {
        const double scale = qx[i] / rho[i];
        qx[i] = scale * px[i];
        qy[i] = scale * py[i];
      }
      for (int pass = 0; pass < kNewtonSteps; ++pass) {
        for (int i = 0; i < n; ++i) {
          const FermatReflection e =
              EvaluateFermatReflection<kOrtho>(lens_x, lens_y, lens_z, mirror, px[i], py[i], pz[i], qx[i], qy[i]);
          double step_x = 0.0, step_y = 0.0;
          const bool descends = FermatNewtonStep(e, &step_x, &step_y);
          // The forward condition at the point the step starts from, where the slopes are.
          ahead[i] = (px[i] - qx[i]) * e.slope_x + (py[i] - qy[i]) * e.slope_y - (pz[i] - e.z);
          qx[i] += step_x;
          qy[i] += step_y;
          // (A sqrt under a condition would keep the loop from vectorising.)
          last_step[i] = std::sqrt(step_x * step_x + step_y * step_y) + (descends ? 0.0 : HUGE_VAL);
        }
      }
      // 3. The mirror point and its pixel.
      for (int i = 0; i < n; ++i) {
        const double x = qx[i], y = qy[i], z = mirror.EvaluateSag(x * x + y * y).z;
        const Vec3<double> mirror_point(r00 * x + r01 * y + r02 * z + t_x, r10 * x + r11 * y + r12 * z + t_y,
                                        r20 * x + r21 * y + r22 * z + t_z);
        Vec2<double> pixel;
        const bool in_front = model.lens.ProjectToPixel(mirror_point, &pixel);
        // NaN fails InImage below. (Selecting the pixel itself would keep the loop scalar.)
        u[i] = pixel.x() + (in_front ? 0.0 : NAN);
        v[i] = pixel.y() + (in_front ? 0.0 : NAN);
        mirror_x[i] = mirror_point.x(), mirror_y[i] = mirror_point.y(), mirror_z[i] = mirror_point.z();
        const double dx = block[3 * i] - mirror_point.x(), dy = block[3 * i + 1] - mirror_point.y(),
                     dz = block[3 * i + 2] - mirror_point.z();
        distance[i] = std::sqrt(dx * dx + dy * dy + dz * dz);
        radius[i] = std::sqrt(x * x + y * y);
      }
    }

    // 4. The checks, without branches ('&' rather than '&&').
    for (int i = 0; i < n; ++i) {
      const double largest = std::max(std::max(std::abs(block[3 * i]), std::abs(block[3 * i + 1])),
                                      std::abs(block[3 * i + 2]));
      accepted[i] = (largest <= detail::kMaxCoordinateMm) & (last_step[i] < 1e-7 * std::min(rim, distance[i])) &
                    (radius[i] >= 0.0) & (radius[i] <= max_radius) & (rho[i] > 1e-12 * rim) & (ahead[i] > 0.0) &
                    model.InImage(u[i], v[i]);
    }

    // 5. Accept, or hand the point to the safeguarded scalar solver.
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d point(block[3 * i], block[3 * i + 1], block[3 * i + 2]);
      bool ok = accepted[i];
      // The camera body, tested on the segment from the mirror point already found (a second
      // solve here would double the cost of every point).
      if (ok && body_radius_mm > 0.0 && point.z() < 0.0 &&
          detail::HitsCameraBody(Eigen::Vector3d(mirror_x[i], mirror_y[i], mirror_z[i]), point, body_radius_mm))
        ok = false;  // the scalar path below reports kOccludedByCamera
      double* out = pixels_uv + 2 * (start + i);
      if (ok) {
        out[0] = u[i];
        out[1] = v[i];
        statuses[start + i] = ProjectionStatus::kOk;
      } else {
        Vec2<double> pixel;
        const ProjectionStatus status = model.Project(point, &pixel, &cache);
        out[0] = status == ProjectionStatus::kOk ? pixel.x() : NAN;
        out[1] = status == ProjectionStatus::kOk ? pixel.y() : NAN;
        statuses[start + i] = status;
      }
    }
  }
}

}  // namespace omnical
