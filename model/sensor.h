// The run-time sensor: one of the compile-time Catadioptric combinations of the registry
// (model/model_registry.h), chosen by the sensor file, plus the precomputation for fast batch projection. The variant is for
// I/O and the CLI; hot loops visit once and then run the concrete type.
#pragma once

#include <Eigen/Core>
#include <string>
#include <variant>
#include <vector>

#include "model/model_registry.h"

namespace omnical {

// The mirror rim radii a sensor file may hold (model/io/sensor_yaml.h); a design fit writes
// only those, so that what it writes loads.
inline constexpr double kMinRimRadiusMm = 1e-3;
inline constexpr double kMaxRimRadiusMm = 1e5;

class Sensor {
 public:
  explicit Sensor(SensorModel model);

  const SensorModel& model() const { return model_; }
  const ProjectionCache& cache() const { return cache_; }

  const char* profile_name() const;
  const char* lens_name() const;
  bool is_axial() const;
  double rim_radius_mm() const;
  int image_width_px() const;
  int image_height_px() const;

  ProjectionStatus Project(const Eigen::Vector3d& point_in_camera, Eigen::Vector2d* pixel) const;
  ProjectionStatus Unproject(const Eigen::Vector2d& pixel, Eigen::Vector3d* origin_in_camera,
                             Eigen::Vector3d* direction_in_camera) const;

  // Batch API: one dispatch, then a tight loop over the concrete model. Outputs are
  // resized; pixels of failed points are NaN.
  void ProjectBatch(const Eigen::Ref<const Eigen::Matrix3Xd>& points_in_camera, Eigen::Matrix2Xd* pixels,
                    std::vector<ProjectionStatus>* statuses) const;
  void UnprojectBatch(const Eigen::Ref<const Eigen::Matrix2Xd>& pixels, Eigen::Matrix3Xd* origins_in_camera,
                      Eigen::Matrix3Xd* directions_in_camera, std::vector<ProjectionStatus>* statuses) const;

 private:
  SensorModel model_;
  ProjectionCache cache_;
};

// Checks a model the way the reader does; returns "field: problem" or empty.
std::string ValidateSensorModel(const SensorModel& model);

}  // namespace omnical
