// Projection of many points with one sensor, in blocks laid out as structure of
// arrays so that the Newton iterations run in loops the compiler vectorises.
//
// Each block takes the table guess, then a fixed number of plain Newton steps (2 for an
// axial sensor: guess error ~0.2 mm -> ~1e-6 mm -> ~1e-16 mm; 3 for the 2-D Fermat
// solve, whose seed ignores the misalignment). A point is accepted only when its last
// step was below the scalar solver's acceptance threshold (detail::AcceptStep) and every
// validity check holds;
// any other point (a poor guess, a point outside the field, NaN) is projected again by
// the safeguarded scalar solver, which also supplies the failure status. The answers are
// those of Catadioptric::Project to its tolerance (~1e-10 px).
#pragma once

#include <algorithm>
#include <cmath>

#include "model/catadioptric.h"

namespace omnical {

template <typename Model>
void ProjectPointsBatch(const Model& model, const ProjectionCache& cache, const double* points_xyz, long count,
                        double* pixels_uv, ProjectionStatus* statuses) {
  constexpr bool kOrtho = Model::kOrthographic;
  constexpr int kBlock = 256;
  const double rim = model.rim_radius_mm;
  const bool axial = model.IsAxial();
  const Eigen::Matrix3d& rotation = cache.camera_from_mirror_rotation;
  const Eigen::Vector3d translation = model.pose.CameraFromMirrorTranslation();
  const Eigen::Vector3d lens = kOrtho ? Eigen::Vector3d(-rotation.row(2).transpose())
                                      : Eigen::Vector3d(-(rotation.transpose() * translation));
  const double m_mm = model.pose.m_mm;

  alignas(64) double px[kBlock], py[kBlock], pz[kBlock], rho[kBlock];
  alignas(64) double qx[kBlock], qy[kBlock], last_step[kBlock], ahead[kBlock];
  alignas(64) double u[kBlock], v[kBlock], distance[kBlock];
  alignas(64) double mirror_x[kBlock], mirror_y[kBlock], mirror_z[kBlock];  // camera frame
  for (long start = 0; start < count; start += kBlock) {
    const int n = static_cast<int>(std::min<long>(kBlock, count - start));
    const double* block = points_xyz + 3 * start;

    // 1. Mirror-frame coordinates and the table guess (table look-ups: scalar).
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d p(block[3 * i] - translation.x(), block[3 * i + 1] - translation.y(),
                        block[3 * i + 2] - translation.z());
      if (!axial) p = rotation.transpose() * p;
      px[i] = p.x(), py[i] = p.y(), pz[i] = p.z();
      rho[i] = std::sqrt(p.x() * p.x() + p.y() * p.y());
      const double guess = cache.guess.valid() ? cache.guess.Guess(rho[i], p.z()) : 0.5 * rim;
      qx[i] = guess;  // the radius in the axial case; the seed point below otherwise
      if (!axial) {
        qx[i] = guess / rho[i] * p.x();
        qy[i] = guess / rho[i] * p.y();
      }
    }

    if (axial) {
      // 2. Fixed Newton steps on G(x) (vectorised).
      for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i < n; ++i) {
          const double x = qx[i];
          const AxialReflection r =
              EvaluateAxialReflection(kOrtho, m_mm, x, model.mirror.EvaluateSag(x * x), rho[i], pz[i]);
          const double step = r.g / r.dg_dx;
          qx[i] = x - step;
          last_step[i] = std::abs(step);
          ahead[i] = r.r_x * (rho[i] - x) + r.r_z * (pz[i] - r.sag_mm);  // forward condition
        }
      }
      // 3. The mirror point and its pixel.
      for (int i = 0; i < n; ++i) {
        const double x = qx[i], scale = x / rho[i];
        const Vec3<double> mirror_point(px[i] * scale + translation.x(), py[i] * scale + translation.y(),
                                        model.mirror.EvaluateSag(x * x).z + translation.z());
        Vec2<double> pixel(NAN, NAN);
        if (!model.lens.ProjectToPixel(mirror_point, &pixel)) pixel.setConstant(NAN);  // fails InImage below
        u[i] = pixel.x(), v[i] = pixel.y();
        mirror_x[i] = mirror_point.x(), mirror_y[i] = mirror_point.y(), mirror_z[i] = mirror_point.z();
        distance[i] = std::sqrt((rho[i] - x) * (rho[i] - x) + (pz[i] - mirror_point.z() + translation.z()) *
                                                                  (pz[i] - mirror_point.z() + translation.z()));
      }
    } else {
      // 2. Fixed Newton steps on the Fermat condition (vectorised).
      for (int pass = 0; pass < 3; ++pass) {
        for (int i = 0; i < n; ++i) {
          const FermatReflection e = EvaluateFermatReflection<kOrtho>(lens.x(), lens.y(), lens.z(), model.mirror,
                                                                      px[i], py[i], pz[i], qx[i], qy[i]);
          double step_x = 0.0, step_y = 0.0;
          const bool descends = FermatNewtonStep(e, &step_x, &step_y);
          qx[i] += step_x;
          qy[i] += step_y;
          last_step[i] = descends ? std::sqrt(step_x * step_x + step_y * step_y) : HUGE_VAL;
          ahead[i] = (px[i] - qx[i]) * e.slope_x + (py[i] - qy[i]) * e.slope_y - (pz[i] - e.z);
        }
      }
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d mirror_point =
            rotation * Eigen::Vector3d(qx[i], qy[i], model.mirror.EvaluateSag(qx[i] * qx[i] + qy[i] * qy[i]).z) +
            translation;
        Vec2<double> pixel(NAN, NAN);
        if (!model.lens.ProjectToPixel(mirror_point, &pixel)) pixel.setConstant(NAN);  // fails InImage below
        u[i] = pixel.x(), v[i] = pixel.y();
        mirror_x[i] = mirror_point.x(), mirror_y[i] = mirror_point.y(), mirror_z[i] = mirror_point.z();
        const Eigen::Vector3d point(block[3 * i], block[3 * i + 1], block[3 * i + 2]);
        distance[i] = (point - mirror_point).norm();
      }
    }

    // 4. Accept, or hand the point to the safeguarded scalar solver.
    for (int i = 0; i < n; ++i) {
      const double radius = axial ? qx[i] : std::sqrt(qx[i] * qx[i] + qy[i] * qy[i]);
      const Eigen::Vector3d point(block[3 * i], block[3 * i + 1], block[3 * i + 2]);
      bool ok = std::abs(point.x()) <= detail::kMaxCoordinateMm && std::abs(point.y()) <= detail::kMaxCoordinateMm &&
                std::abs(point.z()) <= detail::kMaxCoordinateMm &&
                last_step[i] < detail::AcceptStep(rim, distance[i]) && radius >= 0.0 && radius <= rim * detail::kRimSlack &&
                rho[i] > 1e-12 * rim && ahead[i] > 0.0 && model.InImage(u[i], v[i]);
      // The camera body, tested on the segment from the mirror point already found (a second
      // solve here would double the cost of every point).
      if (ok && detail::HitsCameraBody(Eigen::Vector3d(mirror_x[i], mirror_y[i], mirror_z[i]), point,
                                       model.camera_body_radius_mm))
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
