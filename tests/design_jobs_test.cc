// The design and optics jobs through their C++ API alone (no CLI): options checked field by
// field, results against facts that do not come from the job's own code (the seed papers'
// printed values, closed forms), and cancellation by the progress callback.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "model/design/characterize.h"
#include "model/design/design_fit_job.h"
#include "model/design/design_ode_job.h"
#include "model/design/design_spec_yaml.h"
#include "model/input_error.h"
#include "model/progress.h"
#include "model/sensor.h"
#include "model/io/sensor_yaml.h"

namespace omnical {
namespace {

const std::string kData = std::string(OMNICAL_SOURCE_DIR) + "/datasets-synthetic/";

double Parameter(const FitDesign& design, const std::string& name) {
  for (const auto& [key, value] : NormalisedParameters(design))
    if (key == name) return value;
  return NAN;
}

bool StartsWith(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

// A callback that records the stages it hears of and stops the job at `stage`.
ProgressCallback StopAt(const std::string& stage, std::string* stages_seen) {
  return [stage, stages_seen](const ProgressUpdate& update) {
    if (update.done == 0) *stages_seen += update.stage + ";";
    return update.stage != stage;
  };
}

// Ohte & Tsuzuki Table 1, sphere: A = 1.138, m = 4.110 (printed to 4 digits: half a unit
// of the last one), for Omega 135 / Theta 12 deg at the rim.
TEST(DesignFitJob, SphereReproducesTable1) {
  DesignFitOptions options;
  options.spec.profile = "sphere";
  options.spec.rim_omega_deg = 135.0;
  options.spec.rim_theta_deg = 12.0;
  ASSERT_EQ(options.Check(), "");
  const DesignFitResult result = DesignMirrorFit(options);
  EXPECT_NEAR(Parameter(result.design, "A"), 1.138, 5e-4);
  EXPECT_NEAR(Parameter(result.design, "m"), 4.110, 5e-4);
  // The sensor in mm meets the rim targets through its own model (1e-9 deg: round-off).
  EXPECT_NEAR(result.achieved.rim_omega_deg, 135.0, 1e-9);
  EXPECT_NEAR(result.achieved.rim_theta_deg, 12.0, 1e-9);
  EXPECT_NEAR(result.achieved.rim_h_px, 0.5 * options.image_size_px, 1e-9);  // the paper's N
  // The profile table: vertex to rim, on a sphere of radius A M (|sag| = A M - sqrt((A M)^2 - x^2)).
  ASSERT_EQ(result.profile.radius_mm.size(), static_cast<size_t>(options.profile_samples + 1));
  EXPECT_NEAR(result.profile.radius_mm.back(), options.rim_radius_mm, 1e-9);
  const double radius_mm = Parameter(result.design, "A") * options.rim_radius_mm, x = options.rim_radius_mm;
  EXPECT_NEAR(std::abs(result.profile.sag_mm.back()), radius_mm - std::sqrt(radius_mm * radius_mm - x * x), 1e-9);
}

TEST(DesignFitJob, CheckNamesTheField) {
  DesignFitOptions options;
  options.spec.profile = "sphere";
  options.spec.rim_omega_deg = 10.0;  // below Theta
  EXPECT_TRUE(StartsWith(options.Check(), "rim_omega_deg:")) << options.Check();
  try {
    DesignMirrorFit(options);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rim_omega_deg:"), std::string::npos) << e.what();
  }
  options.spec.rim_omega_deg = 135.0;
  options.rim_radius_mm = -1.0;
  EXPECT_TRUE(StartsWith(options.Check(), "rim_radius_mm:")) << options.Check();
  options.rim_radius_mm = 43.9;
  options.spec.profile = "polynomial";
  options.spec.terms = 9;
  EXPECT_TRUE(StartsWith(options.Check(), "terms:")) << options.Check();
}

// A callback returning false during the Ceres solve stops it after that iteration:
// Cancelled, no result.
TEST(DesignFitJob, CallbackReturningFalseCancelsTheFit) {
  DesignFitOptions options;
  options.spec.profile = "polynomial";
  options.spec.characteristic = DefaultCharacteristic("polynomial", 3);
  long last_fit_report = -1;
  options.progress = [&last_fit_report](const ProgressUpdate& update) {
    if (update.stage == "fit") last_fit_report = update.done;
    return !(update.stage == "fit" && update.done >= 2);
  };
  EXPECT_THROW(DesignMirrorFit(options), Cancelled);
  EXPECT_EQ(last_fit_report, 2);  // stopped inside the solve, not before it
}

// Gächter's uniform design (CTU-CMP-2001-03, Sec. 3.2): the rim images at 0.2378 of the
// imager's 0.24 cm (half a unit of the last digit: 5e-4 mm); the centre pixel sees h(0) =
// b on the cylinder, so phi0 = atan(d / (F0 - b)); the lens sits F0 - f below the vertex.
TEST(DesignOdeJob, UniformDesignMatchesTheSeed) {
  DesignOdeOptions options;
  options.spec = LoadOdeDesignSpec(kData + "designs/gaechter-uniform.yaml");
  options.samples = 3001;
  ASSERT_EQ(options.Check(), "");
  std::string stages;
  options.progress = StopAt("none", &stages);
  const DesignOdeResult result = DesignMirrorOde(options);
  EXPECT_EQ(stages, "ode;trace law;");
  EXPECT_NEAR(result.design.rho_end_mm, 2.378, 5e-4);
  EXPECT_TRUE(result.design.ended_at_rim);
  EXPECT_NEAR(result.design.phi0_deg, std::atan(2000.0 / (155.0 + 4000.0)) * 180.0 / M_PI, 0.01);
  EXPECT_NEAR(result.m_mm, 155.0 - 12.5, 1e-9);
  // The law holds through omnical's own ray tracing of the sensor (not the ODE): 1e-5.
  EXPECT_LT(result.max_law_error_rel, 1e-5);
  ASSERT_EQ(result.law_ratio.size(), 5u);
  EXPECT_DOUBLE_EQ(result.reference_curve().distance_mm, 2000.0);
  // The profile table starts at the vertex, and the sensor's image holds the field's end at
  // 0.49 image widths.
  EXPECT_EQ(result.profile.radius_mm.front(), 0.0);
  EXPECT_EQ(result.profile.sag_mm.front(), 0.0);
  EXPECT_NEAR(result.design.rho_end_mm / result.pixel_pitch_mm, 0.49 * options.image_size_px, 1e-9);
}

TEST(DesignOdeJob, CheckNamesTheFieldAndCallbackCancels) {
  DesignOdeOptions options;
  options.spec = LoadOdeDesignSpec(kData + "designs/gaechter-uniform.yaml");
  options.samples = 5;
  EXPECT_TRUE(StartsWith(options.Check(), "samples:")) << options.Check();
  options.samples = 3001;
  options.spec.focal_length_mm = -12.5;
  EXPECT_TRUE(StartsWith(options.Check(), "focal_length_mm:")) << options.Check();
  EXPECT_THROW(DesignMirrorOde(options), InputError);
  options.spec.focal_length_mm = 12.5;
  std::string stages;
  options.progress = StopAt("trace law", &stages);
  EXPECT_THROW(DesignMirrorOde(options), Cancelled);
  EXPECT_EQ(stages, "ode;trace law;");
}

// Table 1's hyperboloid (ohte-svp.yaml) has its lens at the outer focus: one viewpoint, so
// Eq. 6's spread is round-off; its rim targets are Omega 135 / Theta 12 deg (to the 4
// digits of the printed parameters: 0.05 deg).
TEST(CharacterizeJob, SingleViewpointSensorHasNoViewpointSpread) {
  CharacterizeOptions options;
  options.samples = 200;
  ASSERT_EQ(options.Check(), "");
  const CharacterizeResult result = Characterize(LoadSensorYaml(kData + "sensors/ohte-svp.yaml"), options);
  EXPECT_LT(result.viewpoint_spread_mm(), 1e-9);
  EXPECT_NEAR(result.rim_omega_deg(), 135.0, 0.05);
  EXPECT_NEAR(result.rim_theta_deg(), 12.0, 0.05);
  EXPECT_EQ(result.field.size(), 200u);
  EXPECT_EQ(result.blur.size(), 200u);
  EXPECT_TRUE(result.focus_searched);
  EXPECT_TRUE(result.azimuth_curves.empty());  // axial
}

TEST(CharacterizeJob, GivenFocusIsKeptAndTiltedSensorsGetAzimuthCurves) {
  CharacterizeOptions options;
  options.samples = 100;
  options.focus_mm = 300.0;
  const CharacterizeResult result = Characterize(LoadSensorYaml(kData + "sensors/ohte-sph-misaligned.yaml"), options);
  EXPECT_FALSE(result.focus_searched);
  EXPECT_EQ(result.focus_mm, 300.0);
  EXPECT_FALSE(result.axial);
  EXPECT_EQ(result.azimuth_curves.size(), 4u);
}

TEST(CharacterizeJob, CheckNamesTheFieldAndCallbackCancels) {
  CharacterizeOptions options;
  options.f_number = -4.0;
  EXPECT_TRUE(StartsWith(options.Check(), "f_number:")) << options.Check();
  options.f_number = 4.0;
  options.lens_focal_mm = 0.0;
  EXPECT_TRUE(StartsWith(options.Check(), "lens_focal_mm:")) << options.Check();
  options.lens_focal_mm.reset();
  const Sensor sensor = LoadSensorYaml(kData + "sensors/ohte-sph.yaml");
  options.pixel_um = NAN;
  EXPECT_THROW(Characterize(sensor, options), InputError);
  options.pixel_um = 5.2;
  std::string stages;
  options.progress = StopAt("focus", &stages);
  EXPECT_THROW(Characterize(sensor, options), Cancelled);
  EXPECT_EQ(stages, "field;focus;");
}

}  // namespace
}  // namespace omnical
