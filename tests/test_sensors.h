// Sensors for the model tests: every profile with every lens, aligned or misaligned
// (tilt 2 deg + decenter 1 mm, the test case, plus radial and tangential
// distortion on the pinhole), scaled so the rim images at about 480 px from the centre of a 1000 x 1000 image.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "model/sensor.h"

namespace omnical::testing {

struct NamedSensor {
  std::string name;
  SensorModel model;
};

inline constexpr double kRimMm = 43.9;

template <template <typename> class Profile, template <typename> class Lens>
Catadioptric<double, Profile, Lens> MakeModel(const Profile<double>& profile, double m_mm, bool misaligned) {
  Catadioptric<double, Profile, Lens> model;
  model.mirror = profile;
  model.rim_radius_mm = kRimMm;
  model.image_width_px = 1000;
  model.image_height_px = 1000;
  model.pose = {m_mm, 0.0, 0.0, 0.0, 0.0};
  if (misaligned) {
    model.pose.tilt_x_rad = 2.0 * M_PI / 180.0;
    model.pose.tilt_y_rad = -1.2 * M_PI / 180.0;  // 2 deg in total along a skew axis
    model.pose.decenter_x_mm = 0.6;
    model.pose.decenter_y_mm = -0.8;  // 1 mm in total
  }
  const double rim_sag = profile.EvaluateSag(kRimMm * kRimMm).z;
  if constexpr (Lens<double>::kIsOrthographic) {
    model.lens = {480.0 / kRimMm, 499.5, 499.5};
  } else {
    const double f_px = 480.0 * (m_mm + rim_sag) / kRimMm;
    // The misaligned variants carry radial and tangential distortion too, so every harness
    // covers them.
    model.lens = {f_px, f_px * 1.001, 499.5, 499.5, misaligned ? -0.04 : 0.0, misaligned ? 0.02 : 0.0,
                  misaligned ? 0.002 : 0.0, misaligned ? -0.0015 : 0.0};
  }
  return model;
}

// A tabulated profile sampled from the E-DI polynomial (so its shape is known).
inline TabulatedProfile<double> SampledEdiProfile() {
  const EvenPolynomialProfile<double> edi = EvenPolynomialProfile<double>::FromParams(
      std::vector<double>{0.6409 / kRimMm, 0.1550 / std::pow(kRimMm, 3), -0.01 / std::pow(kRimMm, 5)}.data(), 3);
  std::vector<double> r, z;
  for (int i = 0; i <= 120; ++i) {
    r.push_back(1.05 * kRimMm * i / 120.0);
    z.push_back(edi.EvaluateSag(r.back() * r.back()).z);
  }
  TabulatedProfile<double> profile;
  profile.spline = std::make_shared<const ProfileSpline>(r, z);
  profile.source = "sampled-edi";
  return profile;
}

// A spline (model/spline_profile.h) over the rim: the paraboloid sensor's c1 = 1 / (4 A)
// with a figure error in its 6 knots, 0.3 sin(pi j / 5) mm (a 0.3 mm swell and a dip at
// the rim; z'' stays >= 0.84 of the vertex's). A zig-zag of 0.5 mm in the knots, or a
// 1 mm swell, bends the image mapping faster than the remap grid's 2 deg nodes follow
// (0.03 and 0.07 px of interpolation error in tests/remap_test.cc, where 0.01 is promised).
inline SplineProfile<double> BumpedSplineProfile() {
  const std::vector<double> params = {0.5 / kRimMm, 0.1763, 0.2853, 0.2853, 0.1763, 0.0, -0.1763};
  SplineProfile<double> profile = SplineProfile<double>::FromParams(params.data(), static_cast<int>(params.size()));
  profile.span_mm = kRimMm;
  return profile;
}

template <template <typename> class Lens>
std::vector<NamedSensor> SensorsWithLens(const std::string& lens_name, bool misaligned) {
  const double m = 180.0;
  const std::string suffix = "/" + lens_name + (misaligned ? "/misaligned" : "/aligned");
  const EvenPolynomialProfile<double> edi = EvenPolynomialProfile<double>::FromParams(
      std::vector<double>{0.6409 / kRimMm, 0.1550 / std::pow(kRimMm, 3), -0.01 / std::pow(kRimMm, 5)}.data(), 3);
  return {
      {"sphere" + suffix, MakeModel<SphereProfile, Lens>({1.138 * kRimMm}, 4.110 * kRimMm, misaligned)},
      {"polynomial" + suffix, MakeModel<EvenPolynomialProfile, Lens>(edi, 3.919 * kRimMm, misaligned)},
      {"hyperboloid" + suffix,
       MakeModel<HyperboloidProfile, Lens>({0.7407 * kRimMm, 1.698 * kRimMm}, 3.550 * kRimMm, misaligned)},
      {"paraboloid" + suffix, MakeModel<ParaboloidProfile, Lens>({0.5 * kRimMm}, m, misaligned)},
      {"tabulated" + suffix, MakeModel<TabulatedProfile, Lens>(SampledEdiProfile(), 3.919 * kRimMm, misaligned)},
      // A hyperbolic conic (k = -1.5) with two even terms: every part of the formula used.
      {"even_asphere" + suffix, MakeModel<EvenAsphereProfile, Lens>(
                                    EvenAsphereProfile<double>::FromParams(
                                        std::vector<double>{0.9 * kRimMm, -1.5, 0.02 / std::pow(kRimMm, 3),
                                                            -0.004 / std::pow(kRimMm, 5)}.data(), 4),
                                    3.6 * kRimMm, misaligned)},
      {"spline" + suffix, MakeModel<SplineProfile, Lens>(BumpedSplineProfile(), m, misaligned)},
  };
}

inline std::vector<NamedSensor> AllTestSensors() {
  std::vector<NamedSensor> all;
  for (bool misaligned : {false, true}) {
    for (auto& s : SensorsWithLens<PinholeLens>("pinhole", misaligned)) all.push_back(std::move(s));
    for (auto& s : SensorsWithLens<OrthographicLens>("orthographic", misaligned)) all.push_back(std::move(s));
  }
  return all;
}

// A test over every test sensor: INSTANTIATE_TEST_SUITE_P(Models, Fixture,
// ::testing::Range(0, AllTestSensors().size()), TestSensorName).
class EveryTestSensor : public ::testing::TestWithParam<int> {
 protected:
  const NamedSensor& named() const {
    static const std::vector<NamedSensor> all = AllTestSensors();
    return all[GetParam()];
  }
};

inline std::string TestSensorName(const ::testing::TestParamInfo<int>& info) {
  std::string name = AllTestSensors()[info.param].name;
  for (char& c : name)
    if (c == '/') c = '_';
  return name;
}

// Whether every model type of the registry (model/model_registry.h) has an aligned and a
// misaligned test sensor: a profile registered without one fails ModelRegistry tests.
inline std::string ModelTypesWithoutTestSensor() {
  const std::vector<NamedSensor> all = AllTestSensors();
  std::string missing;
  ForEachModelType([&](auto tag) {
    using Model = typename decltype(tag)::type;
    int count = 0;
    for (const NamedSensor& s : all) count += std::holds_alternative<Model>(s.model);
    if (count < 2) missing += std::string(Model::ProfileType::kName) + "/" + Model::LensType::kName + " ";
  });
  return missing;
}

inline std::string SourceDir() { return OMNICAL_SOURCE_DIR; }

// A temporary directory of this process: ctest runs test cases as parallel processes,
// so files with fixed names in the shared temp dir would race.
inline std::string PrivateTempDir() {
  static const std::string dir = [] {
    const std::string path = ::testing::TempDir() + "/omnical-test-" + std::to_string(::getpid());
    std::filesystem::create_directories(path);
    return path;
  }();
  return dir;
}

}  // namespace omnical::testing
