// Render time of one 1000 x 1000 view at 16 samples per pixel (the seed's SPH sensor, an
// aprilgrid 6 mirror radii away, the room environment), on all cores and on one. The
// baseline in the same run is the same render with every sample's ray unprojected
// exactly instead of interpolated between exact pixel-corner rays (correction/pixel_ray_grid.h).
#include <benchmark/benchmark.h>

#include <thread>

#include "calib/synthetic/renderer.h"

namespace omnical {
namespace {

const Scene& NearScene() {
  static const Scene scene = LoadSceneYaml(std::string(OMNICAL_SOURCE_DIR) + "/datasets-synthetic/scenes/ohte-sph-near.yaml");
  return scene;
}

void Render(benchmark::State& state, bool interpolate, int threads) {
  const Scene& scene = NearScene();
  for (auto _ : state) {
    // The ray grid is part of the cost of a first view (later views reuse it).
    const PixelRayGrid rays(*scene.sensor, threads, interpolate);
    cv::Mat image = RenderView(*scene.sensor, rays, scene.views[0], scene.environment, scene.formation, 0, threads);
    benchmark::DoNotOptimize(image.data);
  }
  state.counters["threads"] = threads;
}

const int kAllThreads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

void BM_Render16spp_AllThreads(benchmark::State& state) { Render(state, true, kAllThreads); }
void BM_Render16spp_OneThread(benchmark::State& state) { Render(state, true, 1); }
void BM_Baseline_Render16spp_ExactRays_AllThreads(benchmark::State& state) { Render(state, false, kAllThreads); }

BENCHMARK(BM_Render16spp_AllThreads)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_Render16spp_OneThread)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_Baseline_Render16spp_ExactRays_AllThreads)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace omnical

BENCHMARK_MAIN();
