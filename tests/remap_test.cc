// Virtual screens and remap tables (correction issue): the screen geometry, the exactness
// of the tables for objects on their surface, the axial shortcut against the per-pixel
// path, and the error for objects elsewhere against the independent angle geometry.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <fstream>
#include <iterator>
#include <random>

#include "correction/map_export.h"
#include "correction/remap_error.h"
#include "correction/remap_table.h"
#include "correction/viewpoint_error.h"
#include "model/input_error.h"
#include "model/optics.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

constexpr double kDeg = M_PI / 180.0;

Sensor Shipped(const std::string& name) {
  return LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/" + name + ".yaml");
}

std::vector<VirtualScreen> AllScreens() {
  VirtualScreen panorama;
  panorama.type = VirtualScreen::Type::kPanorama;
  panorama.width_px = 720, panorama.height_px = 160;
  panorama.azimuth0_deg = 37.0, panorama.elevation_top_deg = 35.0, panorama.elevation_bottom_deg = -50.0;
  VirtualScreen lonlat = panorama;
  lonlat.type = VirtualScreen::Type::kLonLat;
  VirtualScreen perspective;
  perspective.type = VirtualScreen::Type::kPerspective;
  perspective.width_px = 320, perspective.height_px = 240;
  perspective.pan_deg = 130.0, perspective.tilt_deg = -10.0, perspective.roll_deg = 7.0, perspective.hfov_deg = 70.0;
  VirtualScreen equiangular;
  equiangular.type = VirtualScreen::Type::kEquiangular;
  equiangular.width_px = equiangular.height_px = 300;
  equiangular.omega_max_deg = 125.0;
  return {panorama, lonlat, perspective, equiangular};
}

// Direction and PixelOf are inverses over every screen.
TEST(VirtualScreen, DirectionAndPixelRoundTrip) {
  std::mt19937 random(4);
  for (const VirtualScreen& screen : AllScreens()) {
    ASSERT_EQ(screen.Check(), "");
    std::uniform_real_distribution<double> col(-0.5, screen.width_px - 0.5), row(-0.5, screen.height_px - 0.5);
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector2d pixel(col(random), row(random));
      Eigen::Vector3d direction;
      if (!screen.Direction(pixel.x(), pixel.y(), &direction)) continue;
      EXPECT_NEAR(direction.norm(), 1.0, 1e-12);
      Eigen::Vector2d back;
      ASSERT_TRUE(screen.PixelOf(3.7 * direction, &back)) << ScreenTypeName(screen.type);
      EXPECT_LT((back - pixel).norm(), 1e-8) << ScreenTypeName(screen.type) << " at " << pixel.transpose();
    }
  }
}

// The documented conventions: panoramas run to decreasing azimuth, a perspective view's
// "right" is forward x z, equiangular radius is proportional to Omega.
TEST(VirtualScreen, FollowsTheDocumentedConventions) {
  std::vector<VirtualScreen> screens = AllScreens();
  Eigen::Vector3d a, b;
  screens[0].Direction(-0.5, 79.5, &a);
  EXPECT_NEAR(std::atan2(a.y(), a.x()), 37.0 * kDeg, 1e-12);
  screens[0].Direction(179.5, 79.5, &b);  // a quarter turn on
  EXPECT_NEAR(std::atan2(b.y(), b.x()), (37.0 - 90.0) * kDeg, 1e-12);
  screens[1].Direction(10.0, -0.5, &a);
  EXPECT_NEAR(std::asin(a.z()), 35.0 * kDeg, 1e-12);  // lonlat: elevation at the top edge
  screens[0].Direction(10.0, 159.5, &a);
  EXPECT_NEAR(std::asin(a.z()), -50.0 * kDeg, 1e-12);  // panorama: at the bottom edge
  VirtualScreen level = screens[2];
  level.roll_deg = 0.0;
  level.Direction(0.5 * (level.width_px - 1), 0.5 * (level.height_px - 1), &a);
  EXPECT_NEAR(std::atan2(a.y(), a.x()), 130.0 * kDeg, 1e-12);
  EXPECT_NEAR(std::asin(a.z()), -10.0 * kDeg, 1e-12);
  level.Direction(level.width_px - 0.5, 0.5 * (level.height_px - 1), &b);  // the right edge
  EXPECT_NEAR(std::acos(a.dot(b)), 35.0 * kDeg, 1e-9);
  EXPECT_LT(std::atan2(b.y(), b.x()), 130.0 * kDeg);  // right is clockwise seen from +z
  level.Direction(0.5 * (level.width_px - 1), level.height_px - 0.5, &b);  // the bottom edge
  EXPECT_LT(b.z(), a.z());                                                  // is lower
  EXPECT_NEAR(level.MirrorFromView().determinant(), 1.0, 1e-12);            // not mirror-imaged
  screens[3].Direction(0.5 * 299 + 75.0, 0.5 * 299, &a);  // half way out along +x
  EXPECT_NEAR(std::acos(-a.z()), 62.5 * kDeg, 1e-12);
  EXPECT_NEAR(a.y(), 0.0, 1e-12);
}

TEST(VirtualScreen, RejectsUnusableGeometry) {
  VirtualScreen screen = AllScreens()[0];
  screen.elevation_top_deg = -60.0;
  EXPECT_NE(screen.Check().find("elevation"), std::string::npos);
  screen = AllScreens()[2];
  screen.hfov_deg = 180.0;
  EXPECT_NE(screen.Check().find("hfov"), std::string::npos);
  screen.width_px = 0;
  EXPECT_NE(screen.Check().find("size"), std::string::npos);
  ObjectSurface surface;
  surface.kind = ObjectSurface::Kind::kSphere;
  surface.distance_mm = 0.0;
  EXPECT_NE(surface.Check().find("distance"), std::string::npos);
  surface.distance_mm = NAN;
  EXPECT_NE(surface.Check().find("distance"), std::string::npos);
}

// Every table entry is the exact projection of its object point (scalar solver vs the
// batch one the table uses), for aligned and misaligned sensors and every surface kind;
// 2e-4 px allows for the float storage of a ~1000-px coordinate (ulp 6e-5).
TEST(RemapTable, EntriesAreExactProjectionsOfTheObjectPoints) {
  for (const char* name : {"ohte-sph", "ohte-sph-misaligned", "ohte-edi"}) {
    const Sensor sensor = Shipped(name);
    for (auto kind : {ObjectSurface::Kind::kInfinity, ObjectSurface::Kind::kSphere, ObjectSurface::Kind::kCylinder,
                      ObjectSurface::Kind::kPlane}) {
      for (const VirtualScreen& screen : AllScreens()) {
        RemapSettings settings;
        settings.screen = screen;
        settings.surface.kind = kind;
        settings.surface.distance_mm = 7.0 * sensor.rim_radius_mm();
        settings.surface.plane_normal = Eigen::Vector3d(0.3, 0.2, -1.0).normalized();
        settings.v0_mm = 11.0;
        settings.threads = 2;
        settings.allow_shortcuts = false;  // the interpolated path has its own test below
        const RemapTable table = BuildRemapTable(sensor, settings);
        long checked = 0;
        for (int v = 0; v < table.height; v += 7) {
          for (int u = 0; u < table.width; u += 11) {
            Eigen::Vector3d point;
            Eigen::Vector2d pixel;
            const bool has_point = RemapObjectPoint(sensor, settings, u, v, &point);
            const ProjectionStatus status =
                has_point ? sensor.Project(sensor.cache().camera_from_mirror_rotation * point +
                                               sensor.cache().camera_from_mirror_translation,
                                           &pixel)
                          : ProjectionStatus::kBehindMirror;
            const size_t i = static_cast<size_t>(v) * table.width + u;
            if (status != ProjectionStatus::kOk) {
              EXPECT_EQ(table.map_x[i], -1.0f) << name << " " << u << "," << v;
              continue;
            }
            ++checked;
            EXPECT_NEAR(table.map_x[i], pixel.x(), 2e-4) << name << " " << ScreenTypeName(screen.type) << " " << u << "," << v;
            EXPECT_NEAR(table.map_y[i], pixel.y(), 2e-4) << name << " " << ScreenTypeName(screen.type) << " " << u << "," << v;
          }
        }
        EXPECT_GT(checked, 50) << name << " " << ScreenTypeName(screen.type) << " " << SurfaceKindName(kind);
      }
    }
  }
}

// The axial shortcut (one projection per row, then rotation) gives the per-pixel tables.
TEST(RemapTable, AxialShortcutMatchesPerPixelProjection) {
  for (const char* name : {"ohte-sph", "ohte-edi", "ohte-svp"}) {
    const Sensor sensor = Shipped(name);
    for (auto kind : {ObjectSurface::Kind::kInfinity, ObjectSurface::Kind::kSphere, ObjectSurface::Kind::kCylinder}) {
      for (int s = 0; s < 2; ++s) {
        RemapSettings settings;
        settings.screen = AllScreens()[s];
        settings.surface.kind = kind;
        settings.surface.distance_mm = 5.0 * sensor.rim_radius_mm();
        settings.v0_mm = 8.0;
        const RemapTable fast = BuildRemapTable(sensor, settings);
        settings.allow_shortcuts = false;
        const RemapTable exact = BuildRemapTable(sensor, settings);
        ASSERT_TRUE(fast.used_axial_symmetry);
        ASSERT_FALSE(exact.used_axial_symmetry);
        EXPECT_EQ(fast.valid_pixels, exact.valid_pixels) << name;
        double worst = 0.0;
        for (size_t i = 0; i < fast.map_x.size(); ++i) {
          if (exact.map_x[i] < 0.0f) continue;
          worst = std::max({worst, double(std::abs(fast.map_x[i] - exact.map_x[i])),
                            double(std::abs(fast.map_y[i] - exact.map_y[i]))});
        }
        EXPECT_LT(worst, 2e-4) << name << " " << SurfaceKindName(kind);  // float storage, as above
      }
    }
  }
}

// The interpolated grid (misaligned sensors, perspective and equiangular screens, planes)
// against the per-pixel tables: the promised 0.01 px everywhere, on every profile with
// both lenses, every screen and near surfaces (n = 2: the map bends most); the same pixels
// valid except where the image border or the field's edge crosses a cell (an output
// pixel there can flip by rounding; at most 0.1 % of them); and mostly interpolated, or
// the path would not be a shortcut.
TEST(RemapTable, InterpolatedGridStaysWithinAHundredthOfAPixel) {
  double worst_all = 0.0;
  for (const testing::NamedSensor& named : testing::AllTestSensors()) {
    if (named.name.find("misaligned") == std::string::npos) continue;
    const Sensor sensor(named.model);
    for (auto kind : {ObjectSurface::Kind::kInfinity, ObjectSurface::Kind::kSphere, ObjectSurface::Kind::kPlane}) {
      for (const VirtualScreen& screen : AllScreens()) {
        RemapSettings settings;
        settings.screen = screen;
        settings.surface.kind = kind;
        settings.surface.distance_mm = 2.0 * sensor.rim_radius_mm();
        settings.surface.plane_normal = Eigen::Vector3d(0.3, 0.2, -1.0).normalized();
        settings.v0_mm = 11.0;
        settings.threads = 2;
        const RemapTable fast = BuildRemapTable(sensor, settings);
        settings.allow_shortcuts = false;
        const RemapTable exact = BuildRemapTable(sensor, settings);
        const std::string what = named.name + " " + ScreenTypeName(screen.type) + " " + SurfaceKindName(kind);
        ASSERT_GE(fast.interpolation_step_px, 2) << what;
        EXPECT_LT(fast.worst_cell_check_px, kCellCheckTolerancePx) << what;
        long both = 0, only_one = 0;
        double worst = 0.0;
        for (size_t i = 0; i < fast.map_x.size(); ++i) {
          const bool in_fast = fast.map_x[i] >= 0.0f, in_exact = exact.map_x[i] >= 0.0f;
          if (in_fast != in_exact) ++only_one;
          if (!in_fast || !in_exact) continue;
          ++both;
          worst = std::max({worst, double(std::abs(fast.map_x[i] - exact.map_x[i])), double(std::abs(fast.map_y[i] - exact.map_y[i]))});
        }
        EXPECT_LT(worst, 0.01) << what;
        EXPECT_LE(only_one, 1e-3 * fast.map_x.size()) << what;
        EXPECT_LT(fast.exact_pixels, 0.3 * exact.valid_pixels) << what;
        std::printf("EXP %s step %d exact %.3f\n", what.c_str(), fast.interpolation_step_px, double(fast.exact_pixels) / exact.valid_pixels);
        worst_all = std::max(worst_all, worst);
      }
    }
  }
  std::printf("worst interpolation error over all tables: %.5f px\n", worst_all);
}

// A sensor whose image cuts the mirror's circle (a common crop): the shortcut's four
// azimuths leave the image in some rows, which then go pixel by pixel; same tables.
TEST(RemapTable, AxialShortcutHandlesACroppedImage) {
  SensorModel model = Shipped("ohte-sph").model();
  std::visit([](auto& m) { m.image_height_px = 700; }, model);  // the circle's bottom third cut off
  const Sensor cropped(model);
  RemapSettings settings;
  settings.screen = AllScreens()[0];
  settings.surface.kind = ObjectSurface::Kind::kInfinity;
  const RemapTable fast = BuildRemapTable(cropped, settings);
  settings.allow_shortcuts = false;
  const RemapTable exact = BuildRemapTable(cropped, settings);
  ASSERT_TRUE(fast.used_axial_symmetry);
  EXPECT_GT(exact.valid_pixels, 0.5 * exact.width * exact.height);
  EXPECT_EQ(fast.valid_pixels, exact.valid_pixels);
  for (size_t i = 0; i < fast.map_x.size(); i += 13) EXPECT_NEAR(fast.map_x[i], exact.map_x[i], 2e-4) << i;
}

// A table is exact at its own distance; an infinity table seen in a lonlat view with
// equal scales along both axes is off by the angle between the object's direction from V0
// and the ray of the pixel it is imaged at (computed here from Project/Unproject alone),
// and that worst error over the field is the seed's Eq. 23 figure (4.75 px at n = 7 in
// the omni image of the seed's sphere; here in degrees against the curve's worst angle,
// 15 %: the curve measures D from the reflection point, the map from V0).
TEST(RemapError, ZeroOnTheSurfaceAndEquation23Elsewhere) {
  const Sensor sensor = Shipped("ohte-sph");
  const double rim = sensor.rim_radius_mm(), distance = 7.0 * rim;
  const std::vector<FieldSample> field = AnalyzeField(sensor, 540, distance);
  RemapSettings settings;
  settings.screen.type = VirtualScreen::Type::kLonLat;
  settings.screen.width_px = 1440, settings.screen.height_px = 360;  // 4 px per degree both ways
  settings.screen.elevation_top_deg = 35.0, settings.screen.elevation_bottom_deg = -55.0;
  settings.v0_mm = BestViewpointMm(field, distance);
  settings.surface.kind = ObjectSurface::Kind::kSphere;
  settings.surface.distance_mm = distance;
  const ObjectSurface object = ObjectAtDistance(settings.surface, distance);
  const RemapErrorStats own = RemapErrorAt(sensor, settings, object, 23);
  EXPECT_GT(own.samples, 500);
  EXPECT_LT(own.max_px, 1e-6);

  settings.surface.kind = ObjectSurface::Kind::kInfinity;
  double worst_deg = 0.0;
  for (int row = 1; row < 360; row += 6) {
    double error_px = 0.0;
    if (!RemapDisplacementPx(sensor, settings, object, 100.0, row, &error_px)) continue;
    Eigen::Vector3d direction, origin, ray;
    settings.screen.Direction(100.0, row, &direction);
    Eigen::Vector2d pixel;
    ASSERT_EQ(sensor.Project(Eigen::Vector3d(0, 0, settings.v0_mm + sensor.cache().camera_from_mirror_translation.z()) +
                                 distance * direction,
                             &pixel),
              ProjectionStatus::kOk);
    ASSERT_EQ(sensor.Unproject(pixel, &origin, &ray), ProjectionStatus::kOk);
    const double angle_deg = std::acos(std::min(1.0, direction.dot(ray.normalized()))) / kDeg;
    EXPECT_NEAR(error_px / 4.0, angle_deg, 1e-3 + 1e-3 * angle_deg) << "row " << row;
    worst_deg = std::max(worst_deg, angle_deg);
  }
  const ParallaxCurve curve = ComputeParallaxCurve(field, distance, settings.v0_mm);
  std::printf("worst %.4f deg over the lonlat column, Eq. 23 curve %.4f deg\n", worst_deg, curve.max_abs_error_deg);
  EXPECT_NEAR(worst_deg, curve.max_abs_error_deg, 0.15 * curve.max_abs_error_deg);
}

// The exported files read back to the table (float maps), and the .npy header is what
// NumPy's format 1.0 expects.
TEST(MapExport, OpenCvMapsRoundTripAndNpyHeaderIsWellFormed) {
  const Sensor sensor = Shipped("ohte-sph");
  RemapSettings settings;
  settings.screen = AllScreens()[0];
  const RemapTable table = BuildRemapTable(sensor, settings);
  const std::string dir = testing::PrivateTempDir();
  WriteOpenCvMaps(table, dir + "/maps.yml.gz", dir + "/maps_fixed.yml.gz");
  const RemapTable back = ReadOpenCvMaps(dir + "/maps.yml.gz");
  ASSERT_EQ(back.width, table.width);
  ASSERT_EQ(back.height, table.height);
  EXPECT_EQ(back.valid_pixels, table.valid_pixels);
  for (size_t i = 0; i < table.map_x.size(); i += 97) EXPECT_EQ(back.map_x[i], table.map_x[i]);
  WriteNpyMaps(table, dir + "/x.npy", dir + "/y.npy");
  std::ifstream npy(dir + "/x.npy", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(npy)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  const size_t header = static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  EXPECT_EQ((10 + header) % 64, 0u);
  EXPECT_EQ(bytes.size(), 10 + header + 4 * table.map_x.size());
  EXPECT_NE(bytes.find("'shape': (160, 720)"), std::string::npos);
  EXPECT_THROW(ReadOpenCvMaps(dir + "/x.npy"), InputError);
}

// Regression (tests/fuzz, maps_yml): a damaged header made OpenCV allocate 32 GB before any
// check. Each file must be refused with InputError naming the map, without allocating.
TEST(MapExport, DamagedMapHeadersAreRefusedBeforeAllocating) {
  const std::string dir = testing::PrivateTempDir();
  const std::string matrix = "   dt: f\n   data: [ 1., 2., 3., 4. ]\n";
  const std::string cases[] = {
      // The fuzzer's input: a non-digit byte in front of cols.
      "%YAML:1.0\n---\nmap_x: !!opencv-matrix\n   rows: 2\n   cols:\xff" "2\n" + matrix,
      "%YAML:1.0\n---\nmap_x: !!opencv-matrix\n   rows: 2000000000\n   cols: 2000000000\n" + matrix,
      "%YAML:1.0\n---\nmap_x: !!opencv-matrix\n   rows: 2\n   cols: 3\n" + matrix,  // 4 values, 6 promised
      "%YAML:1.0\n---\nmap_x: 5\n",
  };
  for (const std::string& text : cases) {
    std::ofstream(dir + "/damaged.yml") << text << "map_y: !!opencv-matrix\n   rows: 2\n   cols: 2\n" << matrix;
    try {
      ReadOpenCvMaps(dir + "/damaged.yml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("map_x"), std::string::npos) << error.what();
    }
  }
  // The fuzzer's own reproducers, kept under tests/data/fuzz-crashes: the 32 GB header, and
  // YAML on which OpenCV's parser throws std::length_error (it escaped as "internal error").
  for (const char* name : {"maps_yml-32gb-alloc.yml", "maps_yml-length-error.yml"})
    EXPECT_THROW(ReadOpenCvMaps(testing::SourceDir() + "/tests/data/fuzz-crashes/" + name), InputError) << name;
}

// The strict reader (opencv_maps_reader.cc) against OpenCV's own: every value cv::FileStorage
// writes, plain or gzip, reads back to the same float bits as cv::FileStorage reads it
// (exact: both parse the decimal text as a double and round it to float).
TEST(MapExport, StrictReaderReadsWhatOpenCvWritesToTheBit) {
  const std::string dir = testing::PrivateTempDir();
  cv::Mat map_x(7, 13, CV_32F), map_y(7, 13, CV_32F);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> pixel(-1.0f, 4000.0f);
  for (int i = 0; i < map_x.rows * map_x.cols; ++i) {
    map_x.at<float>(i) = pixel(random);
    map_y.at<float>(i) = std::ldexp(pixel(random), static_cast<int>(random() % 240) - 140);  // subnormal to 1e34
  }
  map_x.at<float>(0) = -1.0f;  // what remap writes where no mirror is seen
  map_y.at<float>(1) = 1e-41f;  // subnormal
  map_y.at<float>(2) = std::numeric_limits<float>::max();
  for (const std::string name : {"maps.yml", "maps.yml.gz"}) {
    const std::string path = dir + "/" + name;
    {
      cv::FileStorage fs(path, cv::FileStorage::WRITE);
      fs << "map_x" << map_x << "map_y" << map_y;
    }
    cv::Mat opencv_x, opencv_y;
    {
      cv::FileStorage fs(path, cv::FileStorage::READ);
      fs["map_x"] >> opencv_x;
      fs["map_y"] >> opencv_y;
    }
    const RemapTable table = ReadOpenCvMaps(path);
    ASSERT_EQ(table.width, 13);
    ASSERT_EQ(table.height, 7);
    EXPECT_EQ(table.valid_pixels, 7 * 13 - 1);
    for (int i = 0; i < 7 * 13; ++i) {
      EXPECT_EQ(std::memcmp(&table.map_x[i], &opencv_x.at<float>(i), 4), 0) << name << " map_x " << i;
      EXPECT_EQ(std::memcmp(&table.map_y[i], &opencv_y.at<float>(i), 4), 0) << name << " map_y " << i;
    }
  }
}

// Damaged maps files: each refused with InputError naming the file and the matrix or line,
// never a hang (the first case hangs cv::FileStorage 4.6 forever: tests/fuzz, maps_yml).
TEST(MapExport, DamagedMapsFilesAreRefusedNamingFieldOrLine) {
  const std::string dir = testing::PrivateTempDir();
  const std::string head = "%YAML:1.0\n---\n";
  const std::string map_y = "map_y: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ 1., 2. ]\n";
  const std::string long_line(5000, ' ');
  const std::pair<std::string, std::string> cases[] = {
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ .Nan, 2. ]\n" + map_y, "map_x.data: value 1 is not a finite number"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ 1., 3.5e38 ]\n" + map_y, "map_x.data: value 2 is not a finite number"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: d\n   data: [ 1., 2. ]\n" + map_y, "map_x.dt: must be f"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ 1., 2., 3. ]\n" + map_y, "map_x.data: holds more than rows x cols = 2"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ 1.,, 2. ]\n" + map_y, "map_x.data: an empty value after value 1"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ 1., 2. ] x\n" + map_y, "line 7: map_x.data: text after the closing"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ 1.,\n", "map_x.data: ends before its closing"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 0\n", "map_x.cols: must be a whole number 1..20000"},
      {"map_x: !!opencv-matrix\n   cols: 2\n", "line 4: map_x: expected `rows:`"},
      {"map_x: !!opencv-matrix\n   rows: 1\n   cols: 3\n   dt: f\n   data: [ 1., 2., 3. ]\n" + map_y, "map_x/map_y: not two maps of one size"},
      {map_y, "map_x: missing"},
      {map_y + map_y, "line 8: map_y appears twice"},
      {map_y + "map_x: [ 1, 2 ]\n", "line 8: expected `NAME: !!opencv-matrix`"},
      {map_y + "map_x: !!opencv-matrix\n   rows: 1\n" + long_line + "\n", "line 10: is longer than 4096 bytes"},
      {map_y + std::string("map_x\0: x\n", 10), "line 8: holds a NUL byte"},
  };
  for (const auto& [text, expected] : cases) {
    std::ofstream(dir + "/maps.yml", std::ios::binary) << head << text;
    try {
      ReadOpenCvMaps(dir + "/maps.yml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(dir + "/maps.yml: "), std::string::npos) << error.what();
      EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what() << "\nexpected: " << expected;
    }
  }
  // A gzip stream cut short (a half-copied maps.yml.gz) and a file that is not YAML.
  const RemapTable table = BuildRemapTable(Shipped("ohte-sph"), [] {
    RemapSettings settings;
    settings.screen = AllScreens()[0];
    return settings;
  }());
  WriteOpenCvMaps(table, dir + "/maps.yml.gz", dir + "/maps_fixed.yml.gz");
  std::ifstream whole(dir + "/maps.yml.gz", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
  std::ofstream(dir + "/cut.yml.gz", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_THROW(ReadOpenCvMaps(dir + "/cut.yml.gz"), InputError);
  std::ofstream(dir + "/not.yml") << "P5\n2 2\n255\n";
  try {
    ReadOpenCvMaps(dir + "/not.yml");
    ADD_FAILURE() << "accepted a PGM";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("not an OpenCV YAML storage file"), std::string::npos) << error.what();
  }
  EXPECT_THROW(ReadOpenCvMaps(dir + "/absent.yml.gz"), InputError);
  EXPECT_THROW(ReadOpenCvMaps(testing::SourceDir() + "/tests/data/fuzz-crashes/maps_yml-opencv-filestorage-hang.yml"), InputError);
}

}  // namespace
}  // namespace omnical
