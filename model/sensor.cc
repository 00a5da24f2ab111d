#include "model/sensor.h"

#include <limits>

#include "model/batch_projection.h"

namespace omnical {

Sensor::Sensor(SensorModel model) : model_(std::move(model)) {
  cache_ = std::visit([](const auto& m) { return m.MakeCache(); }, model_);
}

const char* Sensor::profile_name() const {
  return std::visit([](const auto& m) { return std::decay_t<decltype(m)>::ProfileType::kName; }, model_);
}
const char* Sensor::lens_name() const {
  return std::visit([](const auto& m) { return std::decay_t<decltype(m)>::LensType::kName; }, model_);
}
bool Sensor::is_axial() const {
  return std::visit([](const auto& m) { return m.IsAxial(); }, model_);
}
double Sensor::rim_radius_mm() const {
  return std::visit([](const auto& m) { return m.rim_radius_mm; }, model_);
}
int Sensor::image_width_px() const {
  return std::visit([](const auto& m) { return m.image_width_px; }, model_);
}
int Sensor::image_height_px() const {
  return std::visit([](const auto& m) { return m.image_height_px; }, model_);
}

ProjectionStatus Sensor::Project(const Eigen::Vector3d& point_in_camera, Eigen::Vector2d* pixel) const {
  return std::visit([&](const auto& m) { return m.Project(point_in_camera, pixel, &cache_); }, model_);
}

ProjectionStatus Sensor::Unproject(const Eigen::Vector2d& pixel, Eigen::Vector3d* origin_in_camera,
                                   Eigen::Vector3d* direction_in_camera) const {
  return std::visit(
      [&](const auto& m) { return m.Unproject(pixel, origin_in_camera, direction_in_camera, &cache_); }, model_);
}

void Sensor::ProjectBatch(const Eigen::Ref<const Eigen::Matrix3Xd>& points_in_camera, Eigen::Matrix2Xd* pixels,
                          std::vector<ProjectionStatus>* statuses) const {
  const Eigen::Index count = points_in_camera.cols();
  pixels->resize(2, count);
  statuses->resize(count);
  // The batch kernel reads packed xyz triples; only a strided view is copied.
  Eigen::Matrix3Xd copy;
  const double* packed = points_in_camera.data();
  if (points_in_camera.outerStride() != 3) {
    copy = points_in_camera;
    packed = copy.data();
  }
  std::visit([&](const auto& m) { ProjectPointsBatch(m, cache_, packed, count, pixels->data(), statuses->data()); },
             model_);
}

void Sensor::UnprojectBatch(const Eigen::Ref<const Eigen::Matrix2Xd>& pixels, Eigen::Matrix3Xd* origins_in_camera,
                            Eigen::Matrix3Xd* directions_in_camera, std::vector<ProjectionStatus>* statuses) const {
  const Eigen::Index count = pixels.cols();
  origins_in_camera->resize(3, count);
  directions_in_camera->resize(3, count);
  statuses->resize(count);
  std::visit(
      [&](const auto& m) {
        for (Eigen::Index i = 0; i < count; ++i) {
          Eigen::Vector3d origin, direction;
          const ProjectionStatus status = m.Unproject(pixels.col(i), &origin, &direction, &cache_);
          if (status != ProjectionStatus::kOk) {
            origin.setConstant(std::numeric_limits<double>::quiet_NaN());
            direction.setConstant(std::numeric_limits<double>::quiet_NaN());
          }
          origins_in_camera->col(i) = origin;
          directions_in_camera->col(i) = direction;
          (*statuses)[i] = status;
        }
      },
      model_);
}

}  // namespace omnical
