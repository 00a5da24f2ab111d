// The C++ side of the Python projection benchmark (python_project_bench.py): the batch
// API's time for the same points, read from the raw float64 file the script wrote.
// Usage: batch_project_time SENSOR.yaml POINTS.f64 REPEATS -> "seconds ok_count" (the
// fastest repeat; the count keeps the work from being optimised away and lets the script
// check both sides agree).
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "model/io/sensor_yaml.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s SENSOR.yaml POINTS.f64 REPEATS\n", argv[0]);
    return 2;
  }
  const omnical::Sensor sensor = omnical::LoadSensorYaml(argv[1]);
  std::ifstream file(argv[2], std::ios::binary | std::ios::ate);
  const long count = static_cast<long>(file.tellg()) / (3 * sizeof(double));
  Eigen::Matrix3Xd points(3, count);
  file.seekg(0);
  file.read(reinterpret_cast<char*>(points.data()), static_cast<std::streamsize>(count * 3 * sizeof(double)));
  if (!file || count == 0) {
    std::fprintf(stderr, "%s: cannot read points\n", argv[2]);
    return 2;
  }
  double fastest = 1e30;
  long ok = 0;
  for (int repeat = 0; repeat < std::stoi(argv[3]); ++repeat) {
    Eigen::Matrix2Xd pixels;
    std::vector<omnical::ProjectionStatus> statuses;
    const auto start = std::chrono::steady_clock::now();
    sensor.ProjectBatch(points, &pixels, &statuses);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fastest = std::min(fastest, seconds);
    ok = 0;
    for (const omnical::ProjectionStatus status : statuses) ok += status == omnical::ProjectionStatus::kOk;
  }
  std::printf("%.9f %ld\n", fastest, ok);
  return 0;
}
