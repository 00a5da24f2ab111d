// Points per second through the batch API, single thread: exact non-central projection
// (axial sphere, tilted + decentred polynomial) and unprojection. The baseline in the
// same run is a plain distorted pinhole projection of the same points (what a central
// model costs at least), so the printed ratios survive a noisy machine.
//
// Points: every 4th pixel of the seed's SPH/E-DI images unprojected, then placed 5 to
// 50 rim radii along the ray (log-uniform, fixed seed): near points are the hard case
// for the table guess (seed Eq. 23 parallax up to ~5 px).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <random>

#include "model/sensor.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

Sensor LoadShipped(const std::string& name) {
  return LoadSensorYaml(std::string(OMNICAL_SOURCE_DIR) + "/datasets-synthetic/sensors/" + name + ".yaml");
}

// The E-DI sensor with the misalignment: tilt 2 deg, decenter 1 mm.
Sensor TiltedPolynomial() {
  SensorModel model = LoadShipped("ohte-edi").model();
  auto& edi = std::get<Catadioptric<double, EvenPolynomialProfile, PinholeLens>>(model);
  edi.pose.tilt_x_rad = 2.0 * M_PI / 180.0;
  edi.pose.decenter_x_mm = 1.0;
  return Sensor(model);
}

struct Workload {
  Eigen::Matrix2Xd pixels;
  Eigen::Matrix3Xd points;
};

Workload MakeWorkload(const Sensor& sensor) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> log_distance(std::log(5.0), std::log(50.0));
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  for (int v = 0; v < sensor.image_height_px(); v += 4) {
    for (int u = 0; u < sensor.image_width_px(); u += 4) {
      Eigen::Vector3d origin, direction;
      if (sensor.Unproject(Eigen::Vector2d(u, v), &origin, &direction) != ProjectionStatus::kOk) continue;
      pixels.emplace_back(u, v);
      points.push_back(origin + std::exp(log_distance(random)) * sensor.rim_radius_mm() * direction);
    }
  }
  Workload workload;
  workload.pixels.resize(2, pixels.size());
  workload.points.resize(3, points.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    workload.pixels.col(i) = pixels[i];
    workload.points.col(i) = points[i];
  }
  return workload;
}

const Sensor& AxialSphere() {
  static const Sensor sensor = LoadShipped("ohte-sph");
  return sensor;
}
const Sensor& Tilted() {
  static const Sensor sensor = TiltedPolynomial();
  return sensor;
}
const Workload& AxialWorkload() {
  static const Workload workload = MakeWorkload(AxialSphere());
  return workload;
}
const Workload& TiltedWorkload() {
  static const Workload workload = MakeWorkload(Tilted());
  return workload;
}

void CheckAllOk(benchmark::State& state, const std::vector<ProjectionStatus>& statuses) {
  for (ProjectionStatus status : statuses) {
    if (status != ProjectionStatus::kOk) {
      state.SkipWithError("a benchmark point failed to project");
      return;
    }
  }
}

// The timed batch answers are the scalar solver's (Sensor::Project, safeguarded Newton
// to ~1e-10 px) within 1e-9 px for every point; the largest difference is reported.
void CheckMatchesScalar(benchmark::State& state, const Sensor& sensor, const Eigen::Matrix3Xd& points,
                        const Eigen::Matrix2Xd& pixels) {
  double worst_px = 0.0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    Eigen::Vector2d pixel;
    if (sensor.Project(points.col(i), &pixel) != ProjectionStatus::kOk) continue;  // CheckAllOk reports it
    worst_px = std::max(worst_px, (pixel - pixels.col(i)).norm());
  }
  state.counters["max_diff_to_scalar_px"] = worst_px;
  if (!(worst_px < 1e-9)) state.SkipWithError("the batch differs from the scalar projection by more than 1e-9 px");
}

void BM_Baseline_PinholeDistortedProjection(benchmark::State& state) {
  const Workload& workload = AxialWorkload();
  const PinholeLens<double> lens{2352.4, 2352.4, 499.5, 499.5, -0.05, 0.01, 0.0, 0.0};
  Eigen::Matrix2Xd pixels(2, workload.points.cols());
  for (auto _ : state) {
    for (Eigen::Index i = 0; i < workload.points.cols(); ++i) {
      Vec2<double> pixel = Vec2<double>::Zero();
      lens.ProjectToPixel(workload.points.col(i), &pixel);
      pixels.col(i) = pixel;
    }
    benchmark::DoNotOptimize(pixels.data());
  }
  state.SetItemsProcessed(state.iterations() * workload.points.cols());
}

void BM_Project_AxialSphere(benchmark::State& state) {
  const Workload& workload = AxialWorkload();
  Eigen::Matrix2Xd pixels;
  std::vector<ProjectionStatus> statuses;
  for (auto _ : state) {
    AxialSphere().ProjectBatch(workload.points, &pixels, &statuses);
    benchmark::DoNotOptimize(pixels.data());
  }
  CheckAllOk(state, statuses);
  CheckMatchesScalar(state, AxialSphere(), workload.points, pixels);
  state.SetItemsProcessed(state.iterations() * workload.points.cols());
}

void BM_Project_TiltedPolynomial(benchmark::State& state) {
  const Workload& workload = TiltedWorkload();
  Eigen::Matrix2Xd pixels;
  std::vector<ProjectionStatus> statuses;
  for (auto _ : state) {
    Tilted().ProjectBatch(workload.points, &pixels, &statuses);
    benchmark::DoNotOptimize(pixels.data());
  }
  CheckAllOk(state, statuses);
  CheckMatchesScalar(state, Tilted(), workload.points, pixels);
  state.SetItemsProcessed(state.iterations() * workload.points.cols());
}

void BM_Unproject_AxialSphere(benchmark::State& state) {
  const Workload& workload = AxialWorkload();
  Eigen::Matrix3Xd origins, directions;
  std::vector<ProjectionStatus> statuses;
  for (auto _ : state) {
    AxialSphere().UnprojectBatch(workload.pixels, &origins, &directions, &statuses);
    benchmark::DoNotOptimize(origins.data());
  }
  CheckAllOk(state, statuses);
  state.SetItemsProcessed(state.iterations() * workload.pixels.cols());
}

void BM_Unproject_TiltedPolynomial(benchmark::State& state) {
  const Workload& workload = TiltedWorkload();
  Eigen::Matrix3Xd origins, directions;
  std::vector<ProjectionStatus> statuses;
  for (auto _ : state) {
    Tilted().UnprojectBatch(workload.pixels, &origins, &directions, &statuses);
    benchmark::DoNotOptimize(origins.data());
  }
  CheckAllOk(state, statuses);
  state.SetItemsProcessed(state.iterations() * workload.pixels.cols());
}

BENCHMARK(BM_Baseline_PinholeDistortedProjection)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Project_AxialSphere)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Project_TiltedPolynomial)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Unproject_AxialSphere)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Unproject_TiltedPolynomial)->Unit(benchmark::kMillisecond);

// Console output as usual, then a summary in million points per second and as a cost
// ratio against the pinhole baseline measured in the same run.
class SummaryReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      // With --benchmark_repetitions the summary takes the medians.
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name != "median") continue;
      const auto it = run.counters.find("items_per_second");
      if (it != run.counters.end()) rates_[run.run_name.function_name] = it->second.value;
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    const double baseline = rates_["BM_Baseline_PinholeDistortedProjection"];
    std::cout << "\nSummary (single thread):\n";
    for (const auto& [name, rate] : rates_) {
      std::printf("  %-42s %8.2f M points/s   cost %6.1f x pinhole baseline\n", name.c_str(), rate / 1e6,
                  baseline / rate);
    }
  }

 private:
  std::map<std::string, double> rates_;
};

}  // namespace
}  // namespace omnical

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  omnical::SummaryReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
