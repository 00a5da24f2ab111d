// Sensor files: the shipped ones load, save -> load is lossless for every model, and bad
// files give one-line errors naming the file and the field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "model/input_error.h"
#include "model/sensor.h"
#include "test_sensors.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = testing::PrivateTempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(SensorYaml, LoadsTheShippedSensors) {
  for (const char* name : {"ohte-sph", "ohte-edi", "ohte-svp"}) {
    const Sensor sensor = LoadSensorYaml(testing::SourceDir() + "/datasets-synthetic/sensors/" + name + ".yaml");
    EXPECT_TRUE(sensor.is_axial());
    EXPECT_STREQ(sensor.lens_name(), "pinhole");
    EXPECT_DOUBLE_EQ(sensor.rim_radius_mm(), 43.9);
    EXPECT_EQ(sensor.image_width_px(), 1000);
  }
}

// Saving and reloading gives the same projections (17 significant digits are written).
TEST(SensorYaml, SaveThenLoadIsLossless) {
  // The tabulated profile needs its table on disk.
  const TabulatedProfile<double> sampled = testing::SampledEdiProfile();
  const std::string table_path = testing::PrivateTempDir() + "/sampled_edi.csv";
  {
    std::ofstream table(table_path);
    table.precision(17);
    table << "r_mm,z_mm\n";
    for (size_t i = 0; i < sampled.spline->radius_mm().size(); ++i)
      table << sampled.spline->radius_mm()[i] << "," << sampled.spline->sag_mm()[i] << "\n";
  }
  for (testing::NamedSensor& named : testing::AllTestSensors()) {
    std::visit(
        [&](auto& model) {
          if constexpr (std::is_same_v<typename std::decay_t<decltype(model)>::ProfileType, TabulatedProfile<double>>) {
            model.mirror.source = table_path;
          }
        },
        named.model);
    const Sensor original(named.model);
    const std::string path = testing::PrivateTempDir() + "/saved_sensor.yaml";
    SaveSensorYaml(original, path);
    const Sensor loaded = LoadSensorYaml(path);
    EXPECT_EQ(loaded.model().index(), original.model().index()) << named.name;
    for (const Eigen::Vector3d& point : {Eigen::Vector3d(300, 40, 100), Eigen::Vector3d(-200, 500, -300)}) {
      Eigen::Vector2d a, b;
      ASSERT_EQ(original.Project(point, &a), loaded.Project(point, &b)) << named.name;
      if (original.Project(point, &a) == ProjectionStatus::kOk) {
        EXPECT_LT((a - b).norm(), 1e-9) << named.name;
      }
    }
  }
}

// p1, p2 are written only where a lens has them, so files without them stay as they were.
TEST(SensorYaml, WritesTangentialTermsOnlyWhenPresent) {
  for (const bool misaligned : {false, true}) {
    const testing::NamedSensor named = testing::SensorsWithLens<PinholeLens>("pinhole", misaligned)[0];
    const std::string path = testing::PrivateTempDir() + "/tangential_sensor.yaml";
    SaveSensorYaml(Sensor(named.model), path);
    std::ifstream file(path);
    const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.find("p1:") != std::string::npos, misaligned) << text;
    EXPECT_EQ(text.find("p2: -0.0015") != std::string::npos, misaligned) << text;
  }
}

struct BadSensor {
  const char* name;
  const char* yaml;
  const char* expected;  // a part of the one-line message
};

const char* kGoodCamera =
    "camera: { model: pinhole, image_size: [1000, 1000], fx: 2352, fy: 2352, cx: 499.5, cy: 499.5 }\n";
const char* kGoodPose = "pose: { m: 180.4 }\n";

// Decentred lenses a real camera has load: one term alone, and small terms on a barrel
// lens (radial slope < 1), whose pull on part of the image's edge the check must allow
// for (found by review: both were refused as leaving image corners without a preimage).
// The sphere design's lens, 1000 x 1000 px at f 800: image corners at normalised 0.88.
TEST(SensorYaml, LoadsDecentredLensesACameraHas) {
  for (const char* lens : {"p1: 0.001", "p2: -0.001", "k1: -0.04, k2: 0.02, p1: 0.002", "k1: -0.1, p1: 0.005, p2: -0.004"}) {
    const std::string yaml = "camera: { model: pinhole, image_size: [1000, 1000], fx: 800, fy: 800, cx: 499.5, cy: 499.5, " +
                             std::string(lens) + " }\nmirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + kGoodPose;
    EXPECT_NO_THROW(ParseSensorYaml(yaml, "decentred")) << lens;
  }
}

class BadSensorFiles : public ::testing::TestWithParam<BadSensor> {};

TEST_P(BadSensorFiles, FailWithOneLineNamingFileAndField) {
  const BadSensor& bad = GetParam();
  WriteTemp("lifted_table.csv", "r,z\n0,1\n1,1.1\n2,1.4\n3,1.9\n");
  WriteTemp("wavy_table.csv", "r,z\n0,0\n1,0.1\n2,0.4\n3,0.5\n4,0.9\n");
  const std::string path = WriteTemp(std::string(bad.name) + ".yaml", bad.yaml);
  try {
    LoadSensorYaml(path);
    FAIL() << "no error for " << bad.name;
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(path, 0), 0u) << message;
    EXPECT_NE(message.find(bad.expected), std::string::npos) << message;
  }
}

std::string Sphere(const std::string& mirror_fields) {
  return std::string(kGoodCamera) + "mirror: { profile: sphere, rim_radius: 43.9, " + mirror_fields + " }\n" + kGoodPose;
}

const std::string kMalformed = std::string(kGoodCamera) + "mirror: { profile: sphere, rim_radius: 43.9, A: [1, \n";
const std::string kUnknownProfile = std::string(kGoodCamera) + "mirror: { profile: cone, rim_radius: 43.9 }\n" + kGoodPose;
const std::string kNegativeRadius = Sphere("A: -49.9");
const std::string kRimBeyondSphere = Sphere("A: 40.0");
const std::string kNegativeRim =
    std::string(kGoodCamera) + "mirror: { profile: sphere, rim_radius: -43.9, A: 49.9 }\n" + kGoodPose;
const std::string kNanFocal =
    "camera: { model: pinhole, image_size: [1000, 1000], fx: .nan, fy: 2352, cx: 499.5, cy: 499.5 }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
const std::string kTextNumber = Sphere("A: fifty");
const std::string kZeroM = std::string(kGoodCamera) + "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" +
                           "pose: { m: 0 }\n";
const std::string kLensInsideMirror = std::string(kGoodCamera) +
                                      "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n"
                                      "pose: { m: 3, tilt_deg: [40, 0], decenter_mm: [0, 30] }\n";
const std::string kUnknownField = Sphere("A: 49.9, radius: 3");
const std::string kMissingPose = std::string(kGoodCamera) + "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n";
const std::string kBadImageSize =
    "camera: { model: pinhole, image_size: [1000, -5], fx: 2352, fy: 2352, cx: 499.5, cy: 499.5 }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
const std::string kBadDistortion =
    "camera: { model: pinhole, image_size: [1000, 1000], fx: 800, fy: 800, cx: 499.5, cy: 499.5, k1: -2.0 }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
// A decentred lens so strong its distortion folds inside the image (x' turns back at y ~ -0.3).
const std::string kFoldingTangential =
    "camera: { model: pinhole, image_size: [1000, 1000], fx: 800, fy: 800, cx: 499.5, cy: 499.5, p1: 0.5 }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
const std::string kHugeTangential =
    "camera: { model: pinhole, image_size: [1000, 1000], fx: 800, fy: 800, cx: 499.5, cy: 499.5, p2: 3 }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
// Found by review: each of these loaded before and then gave wrong pixels or hung.
const std::string kFlatDistortion =  // monotone, but with slope 0.003 (inverse amplifies errors ~300x)
    "camera: { model: pinhole, image_size: [1000, 1000], fx: 600, fy: 600, cx: 499.5, cy: 499.5, k1: -2.4, k2: 2.6 }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
const std::string kBallMirror = std::string(kGoodCamera) +  // rim beyond the silhouette seen from the lens
                                "mirror: { profile: sphere, rim_radius: 43.9, A: 44 }\n" + kGoodPose;
const std::string kConcave =
    std::string(kGoodCamera) + "mirror: { profile: polynomial, rim_radius: 43.9, coefficients: [-0.01] }\n" + kGoodPose;
const std::string kInflected = std::string(kGoodCamera) +
                               "mirror: { profile: polynomial, rim_radius: 43.9, coefficients: [0.01, 0, -8e-10] }\n"
                               "pose: { m: 180, tilt_deg: [1, 0] }\n";
const std::string kFlatMirror =
    std::string(kGoodCamera) + "mirror: { profile: polynomial, rim_radius: 43.9, coefficients: [0.0] }\n" + kGoodPose;
const std::string kTinyFocal =
    "camera: { model: pinhole, image_size: [1000, 1000], fx: 1e-200, fy: 1e-200, cx: 499.5, cy: 499.5 }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
const std::string kHugeRim =
    std::string(kGoodCamera) + "mirror: { profile: sphere, rim_radius: 1e200, A: 1e201 }\n" + kGoodPose;
const std::string kMirrorBehindLens =
    "camera: { model: orthographic, image_size: [2000, 2000], scale_px_per_mm: 10, cx: 999.5, cy: 999.5 }\n"
    "mirror: { profile: paraboloid, rim_radius: 60, A: 20 }\n"
    "pose: { m: 2, tilt_deg: [40, 0] }\n";
const std::string kNonStringKey = "? [a, b]\n: 1\ncamera: {model: pinhole}\n";
const std::string kTableWithoutVertex =
    std::string(kGoodCamera) + "mirror: { profile: tabulated, rim_radius: 3, table: lifted_table.csv }\n" + kGoodPose;
const std::string kWavyTable =
    std::string(kGoodCamera) + "mirror: { profile: tabulated, rim_radius: 4, table: wavy_table.csv }\n" + kGoodPose;

const std::string kUnknownLens =
    "camera: { model: fisheye, image_size: [1000, 1000] }\n"
    "mirror: { profile: sphere, rim_radius: 43.9, A: 49.9 }\n" + std::string(kGoodPose);
const std::string kMissingTable =
    std::string(kGoodCamera) + "mirror: { profile: tabulated, rim_radius: 43.9, table: no-such-table.csv }\n" + kGoodPose;
const std::string kNoCoefficients =
    std::string(kGoodCamera) + "mirror: { profile: polynomial, rim_radius: 43.9, coefficients: [] }\n" + kGoodPose;

INSTANTIATE_TEST_SUITE_P(
    Cases, BadSensorFiles,
    ::testing::Values(BadSensor{"malformed", kMalformed.c_str(), "malformed YAML"},
                      BadSensor{"unknown_profile", kUnknownProfile.c_str(), "mirror.profile: unknown profile 'cone'"},
                      BadSensor{"negative_radius", kNegativeRadius.c_str(), "mirror.A: must be > 0"},
                      BadSensor{"rim_beyond_sphere", kRimBeyondSphere.c_str(), "rim_radius must be smaller"},
                      BadSensor{"negative_rim", kNegativeRim.c_str(), "mirror.rim_radius: must be > 0"},
                      BadSensor{"nan_focal", kNanFocal.c_str(), "camera.fx: must be finite"},
                      BadSensor{"text_number", kTextNumber.c_str(), "mirror.A: 'fifty' is not a number"},
                      BadSensor{"zero_m", kZeroM.c_str(), "pose.m: must be > 0"},
                      BadSensor{"lens_inside_mirror", kLensInsideMirror.c_str(), "pose.m: the lens centre lies inside"},
                      BadSensor{"unknown_field", kUnknownField.c_str(), "mirror.radius: unknown field"},
                      BadSensor{"missing_pose", kMissingPose.c_str(), "pose: missing section"},
                      BadSensor{"bad_image_size", kBadImageSize.c_str(), "camera.image_size"},
                      BadSensor{"bad_distortion", kBadDistortion.c_str(), "camera.k1: radial distortion (k1, k2) folds"},
                      BadSensor{"flat_distortion", kFlatDistortion.c_str(), "camera.k1: radial distortion (k1, k2) folds or flattens"},
                      BadSensor{"folding_tangential", kFoldingTangential.c_str(), "camera.p1: the distortion (k1, k2, p1, p2) folds"},
                      BadSensor{"huge_tangential", kHugeTangential.c_str(), "camera.p2: magnitude must be <= 1"},
                      BadSensor{"ball_mirror_edge_on", kBallMirror.c_str(), "mirror.rim_radius: the lens sees the mirror edge-on"},
                      BadSensor{"concave_mirror", kConcave.c_str(), "mirror: the profile is not convex towards the camera"},
                      BadSensor{"inflected_mirror", kInflected.c_str(), "mirror: the profile is not convex towards the camera at r = 30"},
                      BadSensor{"flat_mirror", kFlatMirror.c_str(), "mirror: the profile is not convex"},
                      BadSensor{"tiny_focal", kTinyFocal.c_str(), "camera.fx: focal lengths below 1e-3 px"},
                      BadSensor{"huge_rim", kHugeRim.c_str(), "mirror.rim_radius: must be <= 100000"},
                      BadSensor{"mirror_behind_lens", kMirrorBehindLens.c_str(), "pose: part of the mirror lies behind the lens plane"},
                      BadSensor{"non_string_key", kNonStringKey.c_str(), "has a key that is not a plain field name"},
                      BadSensor{"table_without_vertex", kTableWithoutVertex.c_str(), "the first row must be the vertex"},
                      BadSensor{"wavy_table", kWavyTable.c_str(), "mirror: the profile is not convex"},
                      BadSensor{"unknown_lens", kUnknownLens.c_str(), "camera.model: unknown lens model 'fisheye'"},
                      BadSensor{"missing_table", kMissingTable.c_str(), "mirror.table: cannot read the profile table:"},
                      BadSensor{"no_coefficients", kNoCoefficients.c_str(), "mirror.coefficients: must list 1 to 8"}),
    [](const ::testing::TestParamInfo<BadSensor>& info) { return std::string(info.param.name); });

TEST(SensorYaml, MissingFileIsReported) {
  try {
    LoadSensorYaml("/nonexistent/sensor.yaml");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "/nonexistent/sensor.yaml: file not found");
  }
}

}  // namespace
}  // namespace omnical
