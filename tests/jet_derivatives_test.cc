// Ceres Jets through projection agree with central differences of the double model, for
// every model parameter and the point, aligned and misaligned. This is what a Ceres
// cost function will see, so it is checked for every profile and lens.
#include <gtest/gtest.h>

#include <ceres/jet.h>

#include <cmath>
#include <vector>

#include "model/sensor.h"
#include "test_sensors.h"

namespace omnical {
namespace {

constexpr int kMaxParams = 24;
using Jet = ceres::Jet<double, kMaxParams>;

template <typename T, template <typename> class Profile>
int ProfileParamCount(const Profile<T>& profile) {
  return profile.NumParams();
}

// Flattens [profile, lens, pose, point] and rebuilds a model of any scalar from them.
template <template <typename> class Profile, template <typename> class Lens>
struct Packed {
  const Catadioptric<double, Profile, Lens>& base;
  int num_profile = 0;

  std::vector<double> Flatten(const Eigen::Vector3d& point) const {
    std::vector<double> values(kMaxParams, 0.0);
    base.mirror.ToParams(values.data());
    base.lens.ToParams(values.data() + num_profile);
    base.pose.ToParams(values.data() + num_profile + Lens<double>::kNumParams);
    for (int k = 0; k < 3; ++k) values[num_profile + Lens<double>::kNumParams + 5 + k] = point[k];
    return values;
  }
  int Count() const { return num_profile + Lens<double>::kNumParams + 5 + 3; }

  template <typename T>
  ProjectionStatus Project(const std::vector<T>& values, Vec2<T>* pixel) const {
    Catadioptric<T, Profile, Lens> model;
    model.mirror = base.mirror.template WithParams<T>(values.data());
    model.lens = Lens<T>::FromParams(values.data() + num_profile);
    model.pose = MirrorPose<T>::FromParams(values.data() + num_profile + Lens<double>::kNumParams);
    model.rim_radius_mm = base.rim_radius_mm;
    model.image_width_px = base.image_width_px;
    model.image_height_px = base.image_height_px;
    const int p = num_profile + Lens<double>::kNumParams + 5;
    return model.Project(Vec3<T>(values[p], values[p + 1], values[p + 2]), pixel);
  }
};

class JetDerivatives : public ::testing::TestWithParam<int> {};

TEST_P(JetDerivatives, AgreeWithCentralDifferences) {
  const testing::NamedSensor named = testing::AllTestSensors()[GetParam()];
  const Sensor sensor(named.model);
  std::visit(
      [&](const auto& model) {
        using Model = std::decay_t<decltype(model)>;
        Packed<Model::template ProfileOf, Model::template LensOf> packed{model, ProfileParamCount(model.mirror)};
        int checked = 0;
        for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(720, 480), Eigen::Vector2d(300, 250),
                                            Eigen::Vector2d(520, 860), Eigen::Vector2d(560, 530)}) {
          Eigen::Vector3d origin, direction;
          ASSERT_EQ(sensor.Unproject(pixel, &origin, &direction), ProjectionStatus::kOk);
          const std::vector<double> values = packed.Flatten(origin + 5.0 * testing::kRimMm * direction);
          std::vector<Jet> jets(kMaxParams);
          for (int k = 0; k < kMaxParams; ++k) jets[k] = Jet(values[k], k);
          Vec2<Jet> jet_pixel;
          ASSERT_EQ(packed.Project(jets, &jet_pixel), ProjectionStatus::kOk);
          for (int k = 0; k < packed.Count(); ++k) {
            // Step: 1e-5 of the parameter's scale (mm lengths ~ the rim, angles and
            // distortion ~ 1). Truncation ~ (step/scale)^2 ~ 1e-10 relative; the solvers
            // converge to ~1e-11 px, far below the ~1e-4 px change over the step.
            const double scale = std::max(std::abs(values[k]), values[k] == 0.0 ? 1.0 : 0.0);
            const double step = 1e-5 * scale;
            std::vector<double> plus = values, minus = values;
            plus[k] += step;
            minus[k] -= step;
            Vec2<double> pixel_plus, pixel_minus;
            ASSERT_EQ(packed.Project(plus, &pixel_plus), ProjectionStatus::kOk);
            ASSERT_EQ(packed.Project(minus, &pixel_minus), ProjectionStatus::kOk);
            for (int axis = 0; axis < 2; ++axis) {
              const double numeric = (pixel_plus(axis) - pixel_minus(axis)) / (2.0 * step);
              const double analytic = jet_pixel(axis).v[k];
              // 1e-6 relative; derivatives whose effect over the step is below 1e-9 px
              // are below what central differences resolve, so they are compared absolutely.
              const double tolerance = std::max(1e-6 * std::max(std::abs(analytic), std::abs(numeric)), 1e-9 / step);
              EXPECT_NEAR(analytic, numeric, tolerance) << named.name << " parameter " << k << " axis " << axis;
              ++checked;
            }
          }
        }
        EXPECT_GE(checked, 4 * 2 * packed.Count());
      },
      sensor.model());
}

// The pinhole's unprojection (the radial solve, or the 2-D one with p1, p2, each with its
// implicit-function step in T): the ray's direction against central differences in every
// lens parameter and the pixel, with and without tangential terms. p1 = p2 = 0 must still
// give their derivatives (a fit frees them from 0).
TEST(PinholeUnprojection, JetsAgreeWithCentralDifferences) {
  using LensJet = ceres::Jet<double, 10>;
  for (const bool decentred : {false, true}) {
    const std::vector<double> values = {1900.0, 1902.0, 503.0, 497.0, -0.04, 0.02,
                                        decentred ? 0.008 : 0.0, decentred ? -0.006 : 0.0, 820.0, 260.0};
    auto direction_of = [](const auto& v) {
      using T = std::decay_t<decltype(v[0])>;
      const PinholeLens<T> lens = PinholeLens<T>::FromParams(v.data());
      Vec3<T> origin, direction;
      lens.PixelToRay(Vec2<T>(v[8], v[9]), &origin, &direction);
      return direction;
    };
    std::vector<LensJet> jets(values.size());
    for (size_t k = 0; k < values.size(); ++k) jets[k] = LensJet(values[k], static_cast<int>(k));
    const Vec3<LensJet> direction = direction_of(jets);
    for (size_t k = 0; k < values.size(); ++k) {
      const double step = 1e-6 * std::max(std::abs(values[k]), 1.0);
      std::vector<double> plus = values, minus = values;
      plus[k] += step, minus[k] -= step;
      const Eigen::Vector3d numeric = (direction_of(plus) - direction_of(minus)) / (2.0 * step);
      for (int axis = 0; axis < 3; ++axis)
        EXPECT_NEAR(direction(axis).v[k], numeric(axis), 1e-6 * std::max(1.0, std::abs(numeric(axis))))
            << (decentred ? "decentred" : "centred") << " parameter " << k << " axis " << axis;
    }
    // The ray projects back to its pixel.
    Vec2<double> pixel;
    const PinholeLens<double> lens = PinholeLens<double>::FromParams(values.data());
    Vec3<double> origin, ray;
    lens.PixelToRay(Vec2<double>(values[8], values[9]), &origin, &ray);
    ASSERT_TRUE(lens.ProjectToPixel(ray, &pixel));
    EXPECT_LT((pixel - Vec2<double>(values[8], values[9])).norm(), 1e-9);
  }
}

INSTANTIATE_TEST_SUITE_P(Models, JetDerivatives, ::testing::Range(0, static_cast<int>(testing::AllTestSensors().size())),
                         [](const ::testing::TestParamInfo<int>& info) {
                           std::string name = testing::AllTestSensors()[info.param].name;
                           for (char& c : name)
                             if (c == '/') c = '_';
                           return name;
                         });

}  // namespace
}  // namespace omnical
