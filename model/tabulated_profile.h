// A mirror profile given as samples (r_i, z_i), e.g. a designed mirror loaded from CSV (the
// file format: model/io/profile_table.h).
//
// Interpolated by a cubic spline in s = r^2: C2, so the curvatures the optics analysis
// needs (f'') are continuous, and smooth across the axis by construction. Natural at the
// vertex; at the last sample natural too, or clamped to the table's slope dz/dr where the
// table has one (a third column): a natural end bent a designed mirror's rim rays by
// 2.6 % of the imaging law (tests/mirror_design_test.cc).
// A table whose vertex row has a slope (dz/dr != 0 at r = 0) is a cone point, which no
// smooth function of r^2 follows (z ~ k sqrt(s)): the reflection ODE makes one whenever
// the centre pixel must see off the axis (Gächter's uniform design, slope 0.23). Such a
// table is splined in r instead, clamped to that slope, and converted to s-derivatives
// (g' = f' / 2r, g'' = (r f'' - f') / 4r^3), exact for every r > 0; the axis itself is
// the cone's singular point.
// ceres::CubicInterpolator is only C1 (Catmull-Rom) on a uniform grid, hence our own.
// The table is data, not a parameter: it is never refined by calibration.
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "model/mirror_profiles.h"

namespace omnical {

class ProfileSpline {
 public:
  // radius_mm strictly increasing from 0; at least 4 samples; end_slope_dz_dr clamps the
  // last knot (NaN: natural); a non-zero vertex_slope_dz_dr makes the vertex a cone point
  // (splined in r, see above). Throws std::invalid_argument with the reason when the
  // samples cannot make a profile.
  ProfileSpline(std::vector<double> radius_mm, std::vector<double> sag_mm, double end_slope_dz_dr = NAN,
                double vertex_slope_dz_dr = 0.0);

  // Index of the segment [k_i, k_i+1] holding the knot variable k (r^2, or r for a cone
  // point), clamped to the first/last segment.
  int Segment(double knot_variable) const;

  template <typename S>
  SagDerivatives<S> Evaluate(const S& r2) const {
    using std::sqrt;
    // Beyond the last sample: continue along the end tangent (in r^2). A cubic would turn
    // over within a few mm and give solvers iterating past the rim spurious roots.
    const int last = static_cast<int>(knots_.size()) - 1;
    if (ScalarPart(r2) > r2_last_) return {S(sag_[last]) + S(end_slope_) * (r2 - S(r2_last_)), S(end_slope_), S(0.0)};
    if (!cone_tip_) return Cubic(r2);
    // The cone's axis is singular; a radius of 1e-9 of the table stands in for it.
    const S r = ScalarPart(r2) > cone_floor_r2_ ? sqrt(r2) : S(std::sqrt(cone_floor_r2_));
    const SagDerivatives<S> f = Cubic(r);  // z, dz/dr, d2z/dr2
    return {f.z, f.dz_ds / (S(2.0) * r), (r * f.d2z_ds2 - f.dz_ds) / (S(4.0) * r * r * r)};
  }

  double max_radius_mm() const { return max_radius_mm_; }
  bool cone_tip() const { return cone_tip_; }
  const std::vector<double>& radius_mm() const { return radius_mm_; }
  const std::vector<double>& sag_mm() const { return sag_; }

 private:
  // The cubic at knot variable k: z and its first two derivatives in k.
  template <typename S>
  SagDerivatives<S> Cubic(const S& k) const {
    const int i = Segment(ScalarPart(k));
    const double h = knots_[i + 1] - knots_[i];
    const S b = (k - S(knots_[i])) / S(h);
    const S a = S(1.0) - b;
    const double mi = second_[i], mj = second_[i + 1];
    const double h2_6 = h * h / 6.0;
    const S z = a * S(sag_[i]) + b * S(sag_[i + 1]) + ((a * a * a - a) * S(mi) + (b * b * b - b) * S(mj)) * S(h2_6);
    const S dz = S((sag_[i + 1] - sag_[i]) / h) - (S(3.0) * a * a - S(1.0)) * S(h * mi / 6.0) +
                 (S(3.0) * b * b - S(1.0)) * S(h * mj / 6.0);
    const S ddz = a * S(mi) + b * S(mj);
    return {z, dz, ddz};
  }

  std::vector<double> radius_mm_;
  std::vector<double> knots_;  // r^2, or r for a cone point
  std::vector<double> sag_;
  std::vector<double> second_;  // d2z/dk2 at the knots
  bool cone_tip_ = false;
  double r2_last_ = 0.0;        // the last sample's r^2
  double end_slope_ = 0.0;      // dz/ds at the last knot
  double cone_floor_r2_ = 0.0;
  double max_radius_mm_ = 0.0;
};

template <typename T>
struct TabulatedProfile {
  static constexpr const char* kName = "tabulated";
  // No parameter: the shape is the table (mirror.table in the sensor file), never fitted.
  static constexpr std::array<ParameterField, 0> kFields{};
  static constexpr int kMaxParams = 0;
  static constexpr int kRimSlopeParam = -1;  // not a design family
  std::shared_ptr<const ProfileSpline> spline;
  std::string source;  // the CSV it came from, written back by the sensor writer

  int NumParams() const { return 0; }
  bool TiltObservable() const { return true; }
  void ToParams(T* /*params*/) const {}
  template <typename U>
  TabulatedProfile<U> WithParams(const U* /*params*/) const {
    return Cast<U>();
  }

  template <typename S>
  SagDerivatives<S> EvaluateSag(const S& r2) const {
    return spline->Evaluate(r2);
  }
  std::string CheckDomain(double rim_radius_mm) const {
    if (!spline) return "no table loaded";
    if (rim_radius_mm > spline->max_radius_mm() * (1.0 + 1e-12))
      return "rim_radius is beyond the last radius of the table";
    return {};
  }
  double MaxRadiusMm() const { return HUGE_VAL; }  // the end cubics extrapolate
  template <typename U>
  TabulatedProfile<U> Cast() const {
    return {spline, source};
  }
};

}  // namespace omnical
