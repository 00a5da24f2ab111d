// A mirror profile given as samples (r_i, z_i), e.g. a designed mirror loaded from CSV.
//
// Interpolated by a cubic spline in s = r^2: C2, so the curvatures the optics analysis
// needs (f'') are continuous, and smooth across the axis by construction. Natural at the
// vertex; at the last sample natural too, or clamped to the table's slope dz/dr where the
// table has one (a third column): a natural end bent a designed mirror's rim rays by
// 2.6 % of the imaging law (tests/mirror_design_test.cc).
// ceres::CubicInterpolator is only C1 (Catmull-Rom) on a uniform grid, hence our own.
// The table is data, not a parameter: it is never refined by calibration.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "model/mirror_profiles.h"

namespace omnical {

class CubicSplineInR2 {
 public:
  // radius_mm strictly increasing from 0; at least 4 samples; end_slope_dz_dr clamps the
  // last knot (NaN: natural). Throws std::invalid_argument with the reason when the
  // samples cannot make a profile.
  CubicSplineInR2(std::vector<double> radius_mm, std::vector<double> sag_mm, double end_slope_dz_dr = NAN);

  // Index of the segment [s_i, s_i+1] holding r2 (clamped to the first/last segment,
  // which then extrapolates with its cubic).
  int Segment(double r2) const;

  template <typename S>
  SagDerivatives<S> Evaluate(const S& r2) const {
    // Beyond the last sample: continue along the end tangent (in r^2). A cubic would turn
    // over within a few mm and give solvers iterating past the rim spurious roots.
    const int last = static_cast<int>(r2_.size()) - 1;
    if (ScalarPart(r2) > r2_[last]) return {S(sag_[last]) + S(end_slope_) * (r2 - S(r2_[last])), S(end_slope_), S(0.0)};
    const int i = Segment(ScalarPart(r2));
    const double h = r2_[i + 1] - r2_[i];
    const S b = (r2 - S(r2_[i])) / S(h);
    const S a = S(1.0) - b;
    const double mi = second_[i], mj = second_[i + 1];
    const double h2_6 = h * h / 6.0;
    const S z = a * S(sag_[i]) + b * S(sag_[i + 1]) +
                ((a * a * a - a) * S(mi) + (b * b * b - b) * S(mj)) * S(h2_6);
    const S dz = S((sag_[i + 1] - sag_[i]) / h) -
                 (S(3.0) * a * a - S(1.0)) * S(h * mi / 6.0) +
                 (S(3.0) * b * b - S(1.0)) * S(h * mj / 6.0);
    const S ddz = a * S(mi) + b * S(mj);
    return {z, dz, ddz};
  }

  double max_radius_mm() const { return max_radius_mm_; }
  const std::vector<double>& radius_mm() const { return radius_mm_; }
  const std::vector<double>& sag_mm() const { return sag_; }

 private:
  std::vector<double> radius_mm_;
  std::vector<double> r2_;
  std::vector<double> sag_;
  std::vector<double> second_;  // d2z/ds2 at the knots
  double end_slope_ = 0.0;      // dz/ds at the last knot
  double max_radius_mm_ = 0.0;
};

template <typename T>
struct TabulatedProfile {
  static constexpr const char* kName = "tabulated";
  static constexpr int kNumParams = 0;
  static constexpr const char* kParamsInfo = "";
  std::shared_ptr<const CubicSplineInR2> spline;
  std::string source;  // the CSV it came from, written back by the sensor writer

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

// Loads "r,z[,dz/dr,...]" rows (mm); a dz/dr column on every row clamps the end slope.
// Throws InputError naming the file, the line and the problem.
std::shared_ptr<const CubicSplineInR2> LoadProfileTable(const std::string& path);

}  // namespace omnical
