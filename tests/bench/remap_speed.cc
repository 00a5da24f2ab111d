// Side by side in one run (ratios, since the machine is noisy): omnical's corrected
// 2048 x 512 panorama table (objects on a sphere at n = 7) against OpenCV's central closed
// form, cv::omnidir::initUndistortRectifyMap with RECTIFY_CYLINDRICAL at the same size,
// single thread and all threads; then the unwarp of a 1000 x 1000 RGB frame against
// cv::remap with the same maps (the seed paper did 15 fps), and a video clip. Each time
// is the median of repeated runs. Writes docs/remap-speed.md. Run:
// build/test/tests/bench/remap_speed
// With --check (a ctest): the misaligned sensor's interpolated table against OpenCV,
// single thread, timed alternately; fails if it is slower (the target) or
// further than 0.01 px from the per-pixel table; and the unwarp on one thread, which
// fails below 1.3x cv::remap's speed or if a byte differs.
#include <opencv2/ccalib/omnidir.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "correction/bilinear_remap.h"
#include "correction/remap_table.h"
#include "correction/unwarp.h"
#include "correction/viewpoint_error.h"
#include "model/io/atomic_write.h"
#include "model/optics.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

const std::string kSource = OMNICAL_SOURCE_DIR;

double MedianSeconds(int repeats, const std::function<void()>& run) {
  std::vector<double> times;
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    run();
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  return times[times.size() / 2];
}

RemapSettings PanoramaAtN7(const Sensor& sensor, int threads) {
  RemapSettings settings;
  settings.screen.type = VirtualScreen::Type::kPanorama;
  settings.screen.width_px = 2048, settings.screen.height_px = 512;
  settings.screen.elevation_top_deg = 35.0, settings.screen.elevation_bottom_deg = -60.0;
  settings.surface.kind = ObjectSurface::Kind::kSphere;
  settings.surface.distance_mm = 7.0 * sensor.rim_radius_mm();
  settings.v0_mm = BestViewpointMm(AnalyzeField(sensor, 360, settings.surface.distance_mm), settings.surface.distance_mm);
  settings.threads = threads;
  return settings;
}

// The worst coordinate difference (px) between two tables where both have a pixel.
double WorstDifferencePx(const RemapTable& a, const RemapTable& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.map_x.size(); ++i)
    if (a.map_x[i] >= 0.0f && b.map_x[i] >= 0.0f)
      worst = std::max({worst, double(std::abs(a.map_x[i] - b.map_x[i])), double(std::abs(a.map_y[i] - b.map_y[i]))});
  return worst;
}

// One 1000 x 1000 RGB frame (the sensor's image) to the 2048 x 512 panorama on `threads`
// (cv::setNumThreads): omnical's unwarp (Unwarper::Apply, linear) against cv::remap with
// the same fixed-point maps and with the float maps, alternated in 9 rounds (medians of 3
// each), so a load drift hits all alike.
struct UnwarpTimes {
  double omnical_s, fixed_s, float_s;  // medians over the rounds
  double speedup;                      // median over the rounds of fixed_s / omnical_s
  bool identical;                      // omnical's bytes are cv::remap's (fixed-point maps)
};

UnwarpTimes TimeUnwarp(const RemapTable& table, int threads) {
  const cv::Mat map_x(table.height, table.width, CV_32F, const_cast<float*>(table.map_x.data()));
  const cv::Mat map_y(table.height, table.width, CV_32F, const_cast<float*>(table.map_y.data()));
  cv::Mat map1, map2, frame(1000, 1000, CV_8UC3), ours, theirs;
  cv::convertMaps(map_x, map_y, map1, map2, CV_16SC2);
  cv::randu(frame, 0, 255);
  const Unwarper unwarper(table, frame.cols, frame.rows, Interpolation::kLinear);
  cv::setNumThreads(threads);
  std::vector<double> omnical_s, fixed_s, float_s, speedups;
  for (int round = 0; round < 9; ++round) {
    fixed_s.push_back(MedianSeconds(3, [&]() { cv::remap(frame, theirs, map1, map2, cv::INTER_LINEAR); }));
    omnical_s.push_back(MedianSeconds(3, [&]() { ours = unwarper.Apply(frame, "frame"); }));
    float_s.push_back(MedianSeconds(3, [&]() { cv::remap(frame, theirs, map_x, map_y, cv::INTER_LINEAR); }));
    speedups.push_back(fixed_s.back() / omnical_s.back());
  }
  cv::remap(frame, theirs, map1, map2, cv::INTER_LINEAR);
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  return {median(omnical_s), median(fixed_s), median(float_s), median(speedups),
          cv::countNonZero(cv::Mat(ours != theirs).reshape(1)) == 0};
}

int Main(bool check) {
  const int all_threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const Sensor aligned = LoadSensorYaml(kSource + "/datasets-synthetic/sensors/ohte-sph.yaml");
  const Sensor misaligned = LoadSensorYaml(kSource + "/datasets-synthetic/sensors/ohte-sph-misaligned.yaml");

  // OpenCV's central model with parameters of the same order as a Mei fit of this
  // sensor (the closed form's cost does not depend on their values).
  const cv::Matx33d K(700.0, 0.0, 499.5, 0.0, 700.0, 499.5, 0.0, 0.0, 1.0);
  const cv::Matx14d D(-0.05, 0.01, 0.0, 0.0);
  const cv::Mat xi = (cv::Mat_<double>(1, 1) << 1.2);
  const cv::Matx33d Knew(2048.0 / 3.1416, 0.0, 0.0, 0.0, 512.0 / 3.1416, 0.0, 0.0, 0.0, 1.0);
  // Each call makes its maps afresh, as BuildRemapTable returns a new table: both pay for
  // new memory (on some virtual machines the page faults of a new table outweigh its computation).
  auto opencv_maps = [&]() {
    cv::Mat cv_map1, cv_map2;
    cv::omnidir::initUndistortRectifyMap(K, D, xi, cv::Matx33d::eye(), Knew, cv::Size(2048, 512), CV_32FC1, cv_map1,
                                         cv_map2, cv::omnidir::RECTIFY_CYLINDRICAL);
  };

  RemapSettings per_pixel = PanoramaAtN7(misaligned, all_threads);
  per_pixel.allow_shortcuts = false;
  const RemapTable reference = BuildRemapTable(misaligned, per_pixel);
  const RemapTable interpolated = BuildRemapTable(misaligned, PanoramaAtN7(misaligned, all_threads));
  const double worst_px = WorstDifferencePx(interpolated, reference);
  if (check) {
    cv::setNumThreads(1);
    const RemapSettings one = PanoramaAtN7(misaligned, 1);
    std::vector<double> ratios;
    for (int i = 0; i < 9; ++i) {
      const double opencv = MedianSeconds(3, opencv_maps);
      ratios.push_back(MedianSeconds(3, [&]() { BuildRemapTable(misaligned, one); }) / opencv);
    }
    std::nth_element(ratios.begin(), ratios.begin() + 4, ratios.end());
    const bool table_ok = ratios[4] <= 1.0 && worst_px < 0.01;
    std::printf("misaligned interpolated table (step %d px, %.1f%% of valid pixels projected one by one): %.2fx OpenCV's time "
                "(bound 1x), %.5f px from the per-pixel table (bound 0.01)\n",
                interpolated.interpolation_step_px, 100.0 * interpolated.exact_pixels / interpolated.valid_pixels, ratios[4],
                worst_px);
    // Measured 1.6-2.9x on the CI's machine (2026-11-24), 3.4-3.7x on a later one (2026-11-28); 1.3x still means the fast path
    // runs and is what the 200 fps rests on.
    const UnwarpTimes unwarp = TimeUnwarp(BuildRemapTable(aligned, PanoramaAtN7(aligned, all_threads)), 1);
    // Without AVX2 the unwarp is cv::remap itself: only the bytes are checked then.
    const cv::Mat probe(1000, 1000, CV_8UC3), map1(512, 2048, CV_16SC2), map2(512, 2048, CV_16UC1);
    const bool fast_path = RemapLinearHasFastPath(probe, map1, map2);
    const bool unwarp_ok = (unwarp.speedup >= 1.3 || !fast_path) && unwarp.identical;
    std::printf("unwarp 1000 x 1000 RGB -> 2048 x 512, 1 thread: %.2fx cv::remap's speed with the same fixed-point maps "
                "(bound 1.3x%s; %.1f against %.1f fps), %s bytes\n%d passed, %d failed\n",
                unwarp.speedup, fast_path ? "" : ", not applied: this CPU has no AVX2", 1.0 / unwarp.omnical_s,
                1.0 / unwarp.fixed_s, unwarp.identical ? "the same" : "DIFFERENT", table_ok + unwarp_ok,
                2 - table_ok - unwarp_ok);
    return table_ok && unwarp_ok ? 0 : 1;
  }

  struct Row {
    std::string what;
    double seconds_1, seconds_all;
  };
  std::vector<Row> rows;
  const int repeats = 15;
  cv::setNumThreads(1);
  const double opencv_1 = MedianSeconds(repeats, opencv_maps);
  cv::setNumThreads(-1);
  const double opencv_all = MedianSeconds(repeats, opencv_maps);
  rows.push_back({"cv::omnidir::initUndistortRectifyMap, RECTIFY_CYLINDRICAL (central closed form)", opencv_1, opencv_all});
  char interpolated_name[200];
  std::snprintf(interpolated_name, sizeof interpolated_name,
                "omnical, misaligned sphere (interpolated grid, step %d px; %.1f%% of pixels projected one by one)",
                interpolated.interpolation_step_px, 100.0 * interpolated.exact_pixels / interpolated.valid_pixels);
  for (const auto& [name, sensor, shortcuts] :
       {std::tuple<std::string, const Sensor*, bool>{"omnical, aligned sphere (axial shortcut)", &aligned, true},
        std::tuple<std::string, const Sensor*, bool>{interpolated_name, &misaligned, true},
        std::tuple<std::string, const Sensor*, bool>{"omnical, misaligned sphere (per-pixel exact projection, the reference)",
                                                     &misaligned, false}}) {
    RemapSettings one = PanoramaAtN7(*sensor, 1), all = PanoramaAtN7(*sensor, all_threads);
    one.allow_shortcuts = all.allow_shortcuts = shortcuts;
    const int n = shortcuts ? repeats : 5;
    rows.push_back({name, MedianSeconds(n, [&]() { BuildRemapTable(*sensor, one); }),
                    MedianSeconds(n, [&]() { BuildRemapTable(*sensor, all); })});
  }

  const RemapTable table = BuildRemapTable(aligned, PanoramaAtN7(aligned, all_threads));
  const UnwarpTimes unwarp_1 = TimeUnwarp(table, 1), unwarp_all = TimeUnwarp(table, -1);
  cv::Mat frame(1000, 1000, CV_8UC3);
  cv::randu(frame, 0, 255);

  // A clip through the unwarper, MJPG in and out (what `omnical unwarp` writes to .avi):
  // frame by frame, decode then remap then encode, against UnwarpFrames, which overlaps
  // the three (correction/unwarp.h). The same frames, maps and codec settings.
  const std::filesystem::path clip_dir =
      std::filesystem::temp_directory_path() / ("omnical-remap-speed-" + std::to_string(::getpid()));
  std::filesystem::create_directories(clip_dir);
  const std::string clip = (clip_dir / "in.avi").string(), unwarped_clip = (clip_dir / "out.avi").string();
  const int clip_frames = 120;
  {
    cv::VideoWriter writer(clip, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, frame.size(), true);
    cv::Mat moving;  // smooth, as a camera frame is (JPEG of white noise is neither typical nor fast)
    cv::GaussianBlur(frame, moving, cv::Size(0, 0), 4.0);
    for (int k = 0; k < clip_frames; ++k) {
      cv::circle(moving, {500, 500}, 10 + 3 * k, cv::Scalar(40 * (k % 6), 255 - 2 * k, 90), 5);
      writer.write(moving);
    }
  }
  const Unwarper unwarper(table, frame.cols, frame.rows, Interpolation::kLinear);
  auto clip_seconds = [&](bool overlapped) {
    cv::VideoCapture capture(clip);
    cv::VideoWriter writer(unwarped_clip, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0,
                           cv::Size(unwarper.width_px(), unwarper.height_px()), true);
    const auto start = std::chrono::steady_clock::now();
    long frames = 0;
    if (overlapped) {
      frames = UnwarpFrames(unwarper, [&](cv::Mat* f) { return capture.read(*f); }, [&](const cv::Mat& f) { writer.write(f); },
                            clip_frames, clip);
    } else {
      for (cv::Mat f; capture.read(f); ++frames) writer.write(unwarper.Apply(f, clip));
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (frames != clip_frames) std::fprintf(stderr, "remap_speed: %ld of %d frames came through\n", frames, clip_frames);
    return seconds;
  };
  cv::setNumThreads(-1);
  std::vector<double> serial_s, overlapped_s;
  for (int run = 0; run < 5; ++run) {  // alternated, so load drifts hit both alike
    serial_s.push_back(clip_seconds(false));
    overlapped_s.push_back(clip_seconds(true));
  }
  std::sort(serial_s.begin(), serial_s.end());
  std::sort(overlapped_s.begin(), overlapped_s.end());
  const double clip_serial = serial_s[2], clip_overlapped = overlapped_s[2];
  std::filesystem::remove_all(clip_dir);

  std::ostringstream md;
  md.precision(3);
  md << "# Remap table speed\n\nWritten by `build/test/tests/bench/remap_speed` (tests/bench/remap_speed.cc); "
     << all_threads << " threads on this machine; medians of repeated runs. 2048 x 512 cylindrical panorama; omnical's "
     << "tables are exact for objects on a sphere at n = 7 mirror radii around the best V0.\n\n"
     << "| map generation | 1 thread (ms) | all threads (ms) | 1 thread vs OpenCV |\n| --- | --- | --- | --- |\n";
  for (const Row& r : rows)
    md << "| " << r.what << " | " << 1e3 * r.seconds_1 << " | " << 1e3 * r.seconds_all << " | " << r.seconds_1 / opencv_1
       << "x |\n";
  md << "\nThe interpolated misaligned table differs from the per-pixel one by at most " << worst_px
     << " px (the promise: < 0.01 px; tests/remap_test.cc checks it over every profile, lens, screen and surface).\n";
  md << "\nUnwarp, 1000 x 1000 RGB frame -> 2048 x 512 (linear; 9 alternated rounds, medians of 3):\n\n"
     << "| | 1 thread (ms) | fps | all threads (ms) | fps |\n| --- | --- | --- | --- | --- |\n";
  const auto fps_row = [&](const char* what, double one_s, double all_s) {
    md << "| " << what << " | " << 1e3 * one_s << " | " << 1.0 / one_s << " | " << 1e3 * all_s << " | " << 1.0 / all_s << " |\n";
  };
  fps_row("omnical (Unwarper::Apply: RemapLinear, AVX2)", unwarp_1.omnical_s, unwarp_all.omnical_s);
  fps_row("cv::remap, the same fixed-point maps (CV_16SC2 + CV_16UC1)", unwarp_1.fixed_s, unwarp_all.fixed_s);
  fps_row("cv::remap, the float maps (CV_32FC1)", unwarp_1.float_s, unwarp_all.float_s);
  md << "\nomnical is " << unwarp_1.speedup << "x cv::remap's speed on 1 thread and " << unwarp_all.speedup
     << "x on all (median of the per-round ratios), with " << (unwarp_1.identical && unwarp_all.identical ? "the same" : "DIFFERENT")
     << " bytes; the seed paper reports 15 fps.\n";
  md << "\nA " << clip_frames << "-frame 1000 x 1000 MJPG clip to a 2048 x 512 MJPG clip (OpenCV's FFmpeg back end, "
     << all_threads << " threads, median of 5): decode, remap and encode one after another " << clip_frames / clip_serial
     << " fps; overlapped (UnwarpFrames: decode and encode on their own threads, as `omnical unwarp` and "
     << "`Unwarper.apply_frames` run) " << clip_frames / clip_overlapped << " fps, " << clip_serial / clip_overlapped
     << "x the throughput.\n";
  std::printf("%s", md.str().c_str());
  WriteFileAtomically(kSource + "/docs/remap-speed.md", [&](std::ostream& out) { out << md.str(); });
  return 0;
}

}  // namespace
}  // namespace omnical

int main(int argc, char** argv) { return omnical::Main(argc > 1 && std::string(argv[1]) == "--check"); }
