// The correction jobs through the library API alone (no CLI): maps.json round trip, the
// remap error sweep, cancellation by callback, and errors that name the request's field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "correction/central_export.h"
#include "correction/maps_error_report.h"
#include "correction/maps_json.h"
#include "correction/parallax_report.h"
#include "correction/remap_outputs.h"
#include "correction/unwarp.h"
#include "model/input_error.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

namespace fs = std::filesystem;

Sensor Shipped(const std::string& name) {
  return LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/" + name + ".yaml");
}

std::string FreshDir(const std::string& name) {
  const std::string dir = testing::PrivateTempDir() + "/" + name;
  fs::remove_all(dir);
  return dir;
}

ViewRequest SmallPanoramaAtN7() {
  ViewRequest view;
  view.view = "panorama";
  view.size = "128x32";
  view.n = 7.0;
  view.threads = 2;
  return view;
}

// The shipped sphere's small panorama at n = 7, as an unwarper of its 1000 x 1000 images.
Unwarper SmallPanoramaUnwarper(Interpolation interpolation) {
  const Sensor sensor = Shipped("ohte-sph");
  RemapOptions remap;
  remap.view = SmallPanoramaAtN7();
  return Unwarper(BuildRemap(sensor, remap).table, sensor.image_width_px(), sensor.image_height_px(), interpolation);
}

// The InputError message of `job`, "" if it throws none.
template <typename Job>
std::string InputErrorOf(Job&& job) {
  try {
    job();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

ProgressCallback StopAfter(const std::string& stage, long done) {
  return [stage, done](const ProgressUpdate& update) { return !(update.stage == stage && update.done >= done); };
}

struct ViewCase {
  const char* view;
  const char* size;
  const char* surface;  // "" : infinity
};

class MapsJsonRoundTrip : public ::testing::TestWithParam<ViewCase> {};

TEST_P(MapsJsonRoundTrip, WrittenThenReadBackGivesTheSameSettingsAndTable) {
  const ViewCase c = GetParam();
  const Sensor sensor = Shipped("ohte-sph-misaligned");
  RemapOptions options;
  options.view.view = c.view, options.view.size = c.size, options.view.threads = 2;
  if (std::string(c.surface).empty()) {
    options.view.infinity = true;
  } else {
    options.view.surface = c.surface, options.view.distance_mm = 600.0;
    if (options.view.surface == "plane") options.view.plane_normal = {1.0, 0.2, -0.5};
  }
  const RemapResult result = BuildRemap(sensor, options);
  const std::string dir = FreshDir(std::string("roundtrip-") + c.view);
  WriteRemapOutputs(dir, result, {MapFormat::kOpenCv}, {"sensor.yaml", "(text)"});

  RemapTable table;
  const MapsDescription read = ReadMapsDescription(dir, &table);
  const RemapSettings& a = result.settings;
  const RemapSettings& b = read.settings;
  EXPECT_EQ(b.screen.type, a.screen.type);
  EXPECT_EQ(b.screen.width_px, a.screen.width_px);
  EXPECT_EQ(b.screen.height_px, a.screen.height_px);
  // The view's own parameters (maps.json holds those of its type) round-trip exactly: JSON
  // numbers carry 17 significant digits. Every output pixel then has the same direction.
  switch (a.screen.type) {
    case VirtualScreen::Type::kPanorama:
    case VirtualScreen::Type::kLonLat:
      EXPECT_EQ(b.screen.azimuth0_deg, a.screen.azimuth0_deg);
      EXPECT_EQ(b.screen.elevation_top_deg, a.screen.elevation_top_deg);
      EXPECT_EQ(b.screen.elevation_bottom_deg, a.screen.elevation_bottom_deg);
      break;
    case VirtualScreen::Type::kPerspective:
      EXPECT_EQ(b.screen.pan_deg, a.screen.pan_deg);
      EXPECT_EQ(b.screen.tilt_deg, a.screen.tilt_deg);
      EXPECT_EQ(b.screen.roll_deg, a.screen.roll_deg);
      EXPECT_EQ(b.screen.hfov_deg, a.screen.hfov_deg);
      break;
    case VirtualScreen::Type::kEquiangular:
      EXPECT_EQ(b.screen.omega_max_deg, a.screen.omega_max_deg);
      break;
  }
  for (int row = 0; row < a.screen.height_px; row += 7)
    for (int col = 0; col < a.screen.width_px; col += 5) {
      Eigen::Vector3d da = Eigen::Vector3d::Zero(), db = Eigen::Vector3d::Zero();
      EXPECT_EQ(a.screen.Direction(col, row, &da), b.screen.Direction(col, row, &db));
      EXPECT_EQ(da, db) << col << ", " << row;
    }
  EXPECT_EQ(b.surface.kind, a.surface.kind);
  EXPECT_EQ(b.surface.distance_mm, a.surface.distance_mm);
  EXPECT_EQ(b.surface.plane_normal, a.surface.plane_normal);
  EXPECT_EQ(b.v0_mm, a.v0_mm);
  EXPECT_EQ(read.sensor_yaml, "(text)");
  EXPECT_EQ(read.sensor_width_px, sensor.image_width_px());
  // The float maps as written (cv::FileStorage keeps float32 exactly).
  ASSERT_EQ(table.map_x.size(), result.table.map_x.size());
  EXPECT_EQ(table.map_x, result.table.map_x);
  EXPECT_EQ(table.map_y, result.table.map_y);
}

INSTANTIATE_TEST_SUITE_P(Views, MapsJsonRoundTrip,
                         ::testing::Values(ViewCase{"panorama", "96x24", "sphere"}, ViewCase{"perspective", "64x48", "plane"},
                                           ViewCase{"equiangular", "64x64", "cylinder"}, ViewCase{"lonlat", "96x24", ""}),
                         [](const ::testing::TestParamInfo<ViewCase>& info) { return std::string(info.param.view); });

TEST(RemapErrorSweep, VanishesAtTheTablesDistanceAndGrowsForNearerObjects) {
  const Sensor sensor = Shipped("ohte-sph-misaligned");
  RemapOptions options;
  options.view = SmallPanoramaAtN7();
  const RemapResult result = BuildRemap(sensor, options);
  const MapsErrorResult curve = MapsErrorReport(MapsDescription{"", "", result.settings, "", 0, 0, "{}"}, sensor);
  ASSERT_GT(curve.errors.size(), 20u);
  EXPECT_TRUE(std::isinf(curve.errors.back().n));
  // 0.01 px: the interpolated tables' bound; the displacement itself is exact there.
  EXPECT_LT(curve.MaxPxAtN(7.0), 0.01);
  // Nearer than the table's distance, the error grows as the objects approach.
  double previous = curve.MaxPxAtN(7.0);
  for (double n : {5.0, 3.0, 2.0}) {
    EXPECT_GT(curve.MaxPxAtN(n), previous + 0.1) << "n = " << n;
    previous = curve.MaxPxAtN(n);
  }
  // The summary in RemapResult is the same sweep at its own preset: n = 7 vanishes too.
  ASSERT_EQ(result.error_at_other_distances.size(), 10u);
  EXPECT_EQ(result.error_at_other_distances[4].n, 7.0);
  EXPECT_LT(result.error_at_other_distances[4].stats.max_px, 0.01);
  EXPECT_GT(result.error_at_other_distances[0].stats.max_px, 1.0);  // n = 1.5
  EXPECT_LT(result.exactness_px, 0.01);
}

TEST(Cancellation, RemapStopsWhenTheCallbackSaysSoAndWritesNothing) {
  const Sensor sensor = Shipped("ohte-sph-misaligned");
  RemapOptions options;
  options.view = SmallPanoramaAtN7();
  options.view.size = "256x64";
  long last_done = -1;
  options.progress = [&](const ProgressUpdate& update) {
    last_done = update.done;
    return !(update.stage == "remap table" && update.done >= 10);
  };
  const std::string dir = FreshDir("cancelled");
  EXPECT_THROW(
      {
        const RemapResult result = BuildRemap(sensor, options);
        WriteRemapOutputs(dir, result, {MapFormat::kOpenCv}, {});
      },
      Cancelled);
  EXPECT_GE(last_done, 10);
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Cancellation, EveryJobThrowsCancelled) {
  const Sensor sensor = Shipped("ohte-sph");
  ParallaxOptions parallax;
  parallax.n = 7.0, parallax.samples = 60, parallax.threads = 2;
  parallax.progress = StopAfter("parallax map", 5);
  EXPECT_THROW(ParallaxReport(sensor, parallax), Cancelled);

  CentralExportOptions central;
  central.step_px = 16.0;
  central.progress = StopAfter("export-central", 1);
  EXPECT_THROW(ExportCentral(sensor, central), Cancelled);

  RemapOptions remap;
  remap.view = SmallPanoramaAtN7();
  const RemapResult result = BuildRemap(sensor, remap);
  MapsErrorOptions sweep;
  sweep.progress = StopAfter("remap error", 2);
  EXPECT_THROW(MapsErrorReport(MapsDescription{"", "", result.settings, "", 0, 0, "{}"}, sensor, sweep), Cancelled);

  const Unwarper unwarper(result.table, sensor.image_width_px(), sensor.image_height_px(), Interpolation::kLinear);
  const cv::Mat frame(sensor.image_height_px(), sensor.image_width_px(), CV_8UC1, cv::Scalar(100));
  long written = 0;
  EXPECT_THROW(UnwarpFrames(
                   unwarper, [&](cv::Mat* f) { return (*f = frame, true); }, [&](const cv::Mat&) { ++written; }, 100, "clip",
                   StopAfter("unwarp", 3)),
               Cancelled);
  EXPECT_EQ(written, 3);
}

// UnwarpFrames overlaps reading, remapping and writing on three threads: the frames must
// still come out in order, each exactly what Apply gives it alone.
TEST(UnwarpFrames, WritesEveryFrameInOrderAsApplyWould) {
  const Unwarper unwarper = SmallPanoramaUnwarper(Interpolation::kLinear);
  std::vector<cv::Mat> inputs;
  for (int k = 0; k < 25; ++k) {
    cv::Mat frame(1000, 1000, CV_8UC3);
    cv::randu(frame, cv::Scalar::all(0), cv::Scalar::all(10 * k + 6));
    inputs.push_back(frame);
  }
  size_t next = 0;
  std::vector<cv::Mat> written;
  const long frames = UnwarpFrames(
      unwarper,
      [&](cv::Mat* f) {
        if (next == inputs.size()) return false;
        *f = inputs[next++].clone();
        return true;
      },
      [&](const cv::Mat& f) { written.push_back(f); }, 0, "clip");
  EXPECT_EQ(frames, 25);
  ASSERT_EQ(written.size(), inputs.size());
  for (size_t k = 0; k < inputs.size(); ++k)
    EXPECT_EQ(cv::norm(written[k], unwarper.Apply(inputs[k], "clip"), cv::NORM_INF), 0.0) << "frame " << k;
}

// A stage that fails ends the others: no hang, the first error reaches the caller, and the
// frames unwarped before a bad frame are still written.
TEST(UnwarpFrames, ReaderWriterAndBadFrameErrorsReachTheCaller) {
  const Unwarper unwarper = SmallPanoramaUnwarper(Interpolation::kLinear);
  const cv::Mat good(1000, 1000, CV_8UC1, cv::Scalar(90)), small(10, 20, CV_8UC1);
  int reads = 0, writes = 0;
  auto endless = [&](cv::Mat* f) { return (*f = good, ++reads, true); };
  EXPECT_EQ(InputErrorOf([&] {
              UnwarpFrames(
                  unwarper, endless,
                  [&](const cv::Mat&) {
                    if (++writes == 4) throw InputError("out.avi: disk full");
                  },
                  0, "clip");
            }),
            "out.avi: disk full");
  EXPECT_EQ(writes, 4);

  reads = writes = 0;
  EXPECT_EQ(InputErrorOf([&] {
              UnwarpFrames(
                  unwarper,
                  [&](cv::Mat* f) {
                    if (++reads == 6) throw InputError("clip: corrupt packet");
                    *f = good;
                    return true;
                  },
                  [&](const cv::Mat&) { ++writes; }, 0, "clip");
            }),
            "clip: corrupt packet");
  EXPECT_EQ(writes, 5);

  reads = writes = 0;
  EXPECT_EQ(InputErrorOf([&] {
              UnwarpFrames(
                  unwarper, [&](cv::Mat* f) { return (*f = ++reads == 3 ? small : good, true); },
                  [&](const cv::Mat&) { ++writes; }, 0, "clip");
            }),
            "clip: is 20 x 10 px but the sensor's image is 1000 x 1000 px");
  EXPECT_EQ(writes, 2);

  EXPECT_EQ(InputErrorOf([&] {
              UnwarpFrames(unwarper, [](cv::Mat*) { return false; }, [](const cv::Mat&) {}, 0, "empty.avi");
            }),
            "empty.avi: has no readable frames");
}

TEST(ViewRequest, ErrorsNameTheField) {
  const Sensor sensor = Shipped("ohte-sph");
  auto error_of = [&](const std::function<void(ViewRequest*)>& change) {
    ViewRequest view = SmallPanoramaAtN7();
    change(&view);
    return InputErrorOf([&] { ResolveView(sensor, view); });
  };
  EXPECT_EQ(error_of([](ViewRequest* v) { v->size = "12"; }), "size: '12' is not WxH (e.g. 2048x512)");
  EXPECT_EQ(error_of([](ViewRequest* v) { v->view = "fisheye"; }), "view: unknown view 'fisheye'");
  EXPECT_EQ(error_of([](ViewRequest* v) { v->n.reset(), v->distance_mm = -5.0; }).rfind("distance_mm: ", 0), 0u);
  EXPECT_EQ(error_of([](ViewRequest* v) { v->n = NAN; }).rfind("n: ", 0), 0u);
  EXPECT_EQ(error_of([](ViewRequest* v) { v->n.reset(); }).rfind("distance_mm: ", 0), 0u);
  EXPECT_EQ(error_of([](ViewRequest* v) { v->infinity = true; }).rfind("n: ", 0), 0u);  // two distances
  EXPECT_EQ(error_of([](ViewRequest* v) { v->plane_normal = {0, 0, 1}; }).rfind("plane_normal: ", 0), 0u);
  EXPECT_EQ(error_of([](ViewRequest* v) { v->v0_mm = NAN; }), "v0_mm: not finite");
  // Finite but absurd (found by fuzzing: no map pixel was finite, reported as a 0 px error).
  EXPECT_EQ(error_of([](ViewRequest* v) { v->v0_mm = 1e300; }), "v0_mm: must lie within 1e6 mm of the mirror vertex");
  EXPECT_EQ(error_of([](ViewRequest* v) { v->n = 1e300; }),
            "n: the object distance must be at most 1e8 mm (100 km; 1e8 stands for infinity)");
  EXPECT_EQ(error_of([](ViewRequest* v) { v->size = "1x1"; }).rfind("size: ", 0), 0u);
  EXPECT_EQ(error_of([](ViewRequest* v) { v->view = "perspective", v->hfov_deg = 180.0; }).rfind("hfov_deg: ", 0), 0u);
  EXPECT_EQ(error_of([](ViewRequest* v) { v->elevation_deg = {-10.0, 10.0}; }).rfind("elevation_deg: ", 0), 0u);
  EXPECT_EQ(error_of([](ViewRequest*) {}), "");
  // A view the mirror cannot see: the job says so, naming the view.
  RemapOptions outside;
  outside.view = SmallPanoramaAtN7();
  outside.view.view = "perspective", outside.view.tilt_deg = 89.0, outside.view.hfov_deg = 20.0;
  EXPECT_EQ(InputErrorOf([&] { BuildRemap(sensor, outside); }).rfind("view: no output pixel sees the mirror", 0), 0u);
  // The other jobs' options too.
  CentralExportOptions central;
  central.step_px = 0.5;
  EXPECT_EQ(InputErrorOf([&] { ExportCentral(sensor, central); }), "step_px: must be >= 1");
  ParallaxOptions parallax;
  EXPECT_EQ(InputErrorOf([&] { ParallaxReport(sensor, parallax); }).rfind("distance_mm: ", 0), 0u);
}

TEST(Unwarper, RefusesFramesOfAnotherSizeNamingTheSource) {
  const Unwarper unwarper = SmallPanoramaUnwarper(Interpolation::kNearest);
  EXPECT_EQ(InputErrorOf([&] { unwarper.Apply(cv::Mat(10, 20, CV_8UC1), "frame.png"); }),
            "frame.png: is 20 x 10 px but the sensor's image is 1000 x 1000 px");
  const cv::Mat out = unwarper.Apply(cv::Mat(1000, 1000, CV_8UC1, cv::Scalar(77)), "frame.png");
  EXPECT_EQ(out.cols, 128);
  EXPECT_EQ(out.rows, 32);
}

}  // namespace
}  // namespace omnical
