// Mirror design (issue 7): the reflection ODE against the seed's designs (Gächter 2001),
// checked through omnical's own ray tracing of the designed sensor, and its errors.
#include <gtest/gtest.h>

#include <cmath>

#include "model/design/designed_sensor.h"
#include "model/design/mirror_design_ode.h"
#include "model/input_error.h"
#include "test_sensors.h"

namespace omnical {
namespace {

// Appendix B.1 of the seed (cm there, mm here).
OdeDesignSpec UniformSpec() {
  OdeDesignSpec spec;
  spec.focal_length_mm = 12.5;
  spec.distance_mm = 2000.0;
  spec.start_height_mm = 155.0;
  spec.rim_limit_mm = 30.0;
  spec.rho0_mm = 0.0;
  spec.rho1_mm = 2.4;
  spec.law.kind = ImagingLaw::Kind::kLinear;
  spec.law.gain = 2000.0;
  spec.law.offset_mm = -4000.0;
  return spec;
}

// Appendix B.2: the SVAVISCA log-polar imager.
OdeDesignSpec LogPolarSpec() {
  OdeDesignSpec spec;
  spec.focal_length_mm = 25.0;
  spec.distance_mm = 2000.0;
  spec.start_height_mm = 215.0;
  spec.rim_limit_mm = 30.0;
  spec.rho0_mm = 252 * 0.0068 / (2.0 * M_PI);
  spec.rho1_mm = 3.56772;
  spec.law.kind = ImagingLaw::Kind::kLogPolar;
  spec.law.gain = 40.0;
  spec.law.offset_mm = -4000.0;
  spec.law.rho0_mm = spec.rho0_mm;
  spec.law.growth_rate = 1.02337;
  return spec;
}

// The seed's uniform design: phi0 is exactly atan(d / (F0 - b)) (the axis ray meets the
// cylinder at h = b), to the 0.01 deg; phi1 and the field against the independent
// reference of SEED-NOTES.md (106.5 and 80.8 deg, computed at 0.999 t1 as the seed's
// listing does: the rim itself gives 106.58; 0.1 deg covers that).
TEST(MirrorDesignOde, UniformDesignMatchesTheSeed) {
  const OdeDesignSpec spec = UniformSpec();
  const OdeDesign design = SolveMirrorOde(spec);
  EXPECT_NEAR(design.phi0_deg, std::atan(2000.0 / (155.0 + 4000.0)) * 180.0 / M_PI, 0.01);
  EXPECT_NEAR(design.phi1_deg, 106.5, 0.1);
  EXPECT_NEAR(design.phi1_deg - design.phi0_deg, 80.8, 0.1);
  // The rim images at 2.378 of the imager's 2.4 mm: the field ends at the rim, as the
  // listing clips it.
  EXPECT_TRUE(design.ended_at_rim);
  EXPECT_NEAR(design.rho_end_mm, 2.378, 0.001);
}

// Log-polar: phi1 = 96.4 deg (the seed prints 96.3 from its finite differences), phi0
// 25.4 at rho0 (SEED-NOTES.md).
TEST(MirrorDesignOde, LogPolarDesignMatchesTheSeed) {
  const OdeDesign design = SolveMirrorOde(LogPolarSpec());
  EXPECT_NEAR(design.phi1_deg, 96.4, 0.05);
  EXPECT_NEAR(design.phi0_deg, 25.4, 0.05);
  EXPECT_FALSE(design.ended_at_rim);
}

// The law through omnical's own ray tracing (the tabulated sensor, its spline and the
// model's reflection solver; not the ODE's formula): the ratio of Fig. 10/14 at the
// reference distance, within the 1e-6 over the whole imager: from rho0 for the
// log-polar design, from 0.1 % of the field for the uniform one, whose centre pixel looks
// along the axis at the cone point the ODE gives its vertex (slope 0.23). A natural spline
// end (no slope clamp) gave 2.6e-2 at the rim; splining that cone in r^2 gave 9e-4 in the
// innermost 1 % (tabulated_profile.h).
TEST(MirrorDesignOde, ImagingLawHoldsThroughTheTracedSensor) {
  for (const OdeDesignSpec& spec : {LogPolarSpec(), UniformSpec()}) {
    const OdeDesign design = SolveMirrorOde(spec, 20001);
    const Sensor sensor = SensorFromOdeDesign(spec, design, 1000, "profile.csv");
    const double pitch = PixelPitchMm(design, 1000);
    const bool uniform = spec.law.kind == ImagingLaw::Kind::kLinear;
    const double from = uniform ? 1e-3 * design.rho_end_mm : spec.rho0_mm;
    const LawRatioCurve curve = TraceLawRatio(sensor, spec, pitch, spec.distance_mm, from, design.rho_end_mm, 100);
    double worst = 0.0;
    for (double r : curve.ratio) {
      ASSERT_TRUE(std::isfinite(r));
      worst = std::max(worst, std::abs(r - 1.0));
    }
    EXPECT_LT(worst, 1e-6) << (uniform ? "uniform" : "log-polar");
    // Away from the design distance the law degrades (the seed's Fig. 10: a few 1e-3 to
    // 1e-2 for the uniform mirror at 1 m), so the check above is not vacuous.
    const LawRatioCurve near = TraceLawRatio(sensor, spec, pitch, 0.5 * spec.distance_mm, from, design.rho_end_mm, 100);
    double near_worst = 0.0;
    for (double r : near.ratio) near_worst = std::max(near_worst, std::abs(r - 1.0));
    EXPECT_GT(near_worst, 1e-3);
  }
}

// Bad designs name the cause and where it happened.
TEST(MirrorDesignOde, RejectsDesignsThatCannotBeBuilt) {
  auto message = [](const OdeDesignSpec& spec) {
    try {
      SolveMirrorOde(spec, 200);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  OdeDesignSpec spec = UniformSpec();
  spec.rho1_mm = 3.0;  // the rim images at 2.378 mm
  EXPECT_NE(message(spec).find("beyond the image of the rim"), std::string::npos) << message(spec);
  spec = UniformSpec();
  spec.law.gain = -2000.0;
  EXPECT_NE(message(spec).find("law.gain"), std::string::npos);
  spec = UniformSpec();
  spec.law.kind = ImagingLaw::Kind::kTable;
  spec.law.table_rho_mm = {0.0, 1.0, 2.0, 3.0};
  spec.law.table_h_mm = {-4000.0, -2000.0, -2500.0, 2000.0};
  EXPECT_NE(message(spec).find("not monotone"), std::string::npos) << message(spec);
  // A law asking for points far below the camera: the profile steepens until it folds
  // back; a little less, and a reflected ray heads back to the axis.
  spec = UniformSpec();
  spec.law.gain = 1.0, spec.law.offset_mm = -1e6;
  const std::string fold = message(spec);
  EXPECT_NE(fold.find("folds back"), std::string::npos) << fold;
  EXPECT_NE(fold.find("at t = 0.44"), std::string::npos) << fold;
  spec.law.offset_mm = -1e5;
  EXPECT_NE(message(spec).find("turns back to the axis"), std::string::npos) << message(spec);
}

// A law given as a table reproduces the linear design it samples.
TEST(MirrorDesignOde, TableLawMatchesTheClosedForm) {
  OdeDesignSpec table = UniformSpec();
  table.law.kind = ImagingLaw::Kind::kTable;
  for (int i = 0; i <= 10; ++i) {
    table.law.table_rho_mm.push_back(0.3 * i);
    table.law.table_h_mm.push_back(2000.0 * 0.3 * i - 4000.0);
  }
  const OdeDesign a = SolveMirrorOde(UniformSpec(), 301), b = SolveMirrorOde(table, 301);
  EXPECT_NEAR(a.phi1_deg, b.phi1_deg, 1e-9);
  EXPECT_NEAR(a.profile.back().height_mm, b.profile.back().height_mm, 1e-9);
}

}  // namespace
}  // namespace omnical
