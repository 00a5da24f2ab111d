// Loads a sensor file with the installed library, projects a point, unprojects the
// pixel and checks the ray passes through the point.
#include <Eigen/Geometry>
#include <cstdio>

#include "model/sensor.h"
#include "model/io/sensor_yaml.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const omnical::Sensor sensor = omnical::LoadSensorYaml(argv[1]);
  const Eigen::Vector3d point(400.0, -150.0, 60.0);
  Eigen::Vector2d pixel;
  if (sensor.Project(point, &pixel) != omnical::ProjectionStatus::kOk) return 1;
  Eigen::Vector3d origin, direction;
  if (sensor.Unproject(pixel, &origin, &direction) != omnical::ProjectionStatus::kOk) return 1;
  const double miss_mm = (point - origin).cross(direction).norm();
  std::printf("pixel %.6f %.6f, ray misses the point by %.3g mm\n", pixel.x(), pixel.y(), miss_mm);
  return miss_mm < 1e-6 ? 0 : 1;
}
