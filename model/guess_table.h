// Initial guess for the reflection radius of an axial sensor (NONCENTRAL-NOTES): the
// direction of the point seen from a reference viewpoint z_ref gives Omega, and the
// table inverts the monotone map x -> Omega(x). The guess error is exactly the seed's
// Eq. 23 parallax. One refinement repeats the look-up from the viewpoint z_v of the
// guessed ray (tabulated too), which removes most of it for near points at the cost of
// one sqrt; 1-2 Newton steps then finish. The table is indexed by
// w = tan(Omega / 2) = rho / (|P - V| + z_V - h), which needs one sqrt and no trig.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/axial_reflection.h"
#include "model/simd_clones.h"

namespace omnical {

class AxialGuessTable {
 public:
  AxialGuessTable() = default;

  // Tabulates the sensor's axial cross-section (tilt and decenter ignored: for a tilted
  // sensor the guess only seeds the 2-D solver). valid() is false when Omega is not
  // monotone in x (some tabulated profiles); the solver then brackets instead.
  template <typename Profile>
  AxialGuessTable(bool orthographic, double m_mm, const Profile& mirror, double rim_radius_mm) {
    constexpr int kSamples = 4097;
    constexpr int kEntries = 2048;
    std::vector<double> x(kSamples), w(kSamples), z_v(kSamples);
    for (int j = 0; j < kSamples; ++j) {
      x[j] = rim_radius_mm * j / (kSamples - 1);
      const AxialReflection r =
          EvaluateAxialReflection(orthographic, m_mm, x[j], mirror.EvaluateSag(x[j] * x[j]), 0.0, 0.0);
      const double norm = std::hypot(r.r_x, r.r_z);
      w[j] = r.r_x / (norm - r.r_z);
      if (j > 0 && !(w[j] > w[j - 1])) return;  // not monotone: no table
      if (j > 0) z_v[j] = r.sag_mm - x[j] * r.r_z / r.r_x;  // seed Eq. 6
    }
    z_v[0] = z_v[1];  // the paraxial limit
    std::vector<double> sorted = z_v;
    std::nth_element(sorted.begin(), sorted.begin() + kSamples / 2, sorted.end());
    z_ref_mm_ = sorted[kSamples / 2];
    w_max_ = w.back();
    inv_dw_ = (kEntries - 1) / w_max_;
    x_of_w_.resize(kEntries + 1);
    viewpoint_of_w_.resize(kEntries + 1);
    int j = 0;
    for (int i = 0; i < kEntries; ++i) {
      const double wi = w_max_ * i / (kEntries - 1);
      while (j + 2 < kSamples && w[j + 1] < wi) ++j;
      const double t = std::clamp((wi - w[j]) / (w[j + 1] - w[j]), 0.0, 1.0);
      x_of_w_[i] = x[j] + t * (x[j + 1] - x[j]);
      viewpoint_of_w_[i] = z_v[j] + t * (z_v[j + 1] - z_v[j]);
    }
    // Guards for the interpolation at w_max.
    x_of_w_[kEntries] = x_of_w_[kEntries - 1];
    viewpoint_of_w_[kEntries] = viewpoint_of_w_[kEntries - 1];
    valid_ = true;
  }

  bool valid() const { return valid_; }
  double reference_viewpoint_mm() const { return z_ref_mm_; }

  // Guessed reflection radius for a point at radius rho and height h (mirror frame).
  double Guess(double rho, double h) const {
    double position = Position(rho, h, z_ref_mm_, w_max_, inv_dw_);
    position = Position(rho, h, Lerp(viewpoint_of_w_.data(), position), w_max_, inv_dw_);
    return Lerp(x_of_w_.data(), position);
  }

  // Guess for many points, the same arithmetic as Guess. The table positions (a sqrt
  // and a division each) are computed in loops the compiler vectorises; the table
  // reads stay scalar (GCC does not vectorise them into gathers for generic x86-64).
  OMNICAL_CLONE_FOR_AVX2 void GuessMany(const double* rho, const double* h, int count, double* x_out) const {
    // Locals, which the stores to x_out cannot alias.
    const double* x_table = x_of_w_.data();
    const double* viewpoint_table = viewpoint_of_w_.data();
    const double z_ref_mm = z_ref_mm_, w_max = w_max_, inv_dw = inv_dw_;
    for (int i = 0; i < count; ++i) x_out[i] = Position(rho[i], h[i], z_ref_mm, w_max, inv_dw);
    for (int i = 0; i < count; ++i) x_out[i] = Lerp(viewpoint_table, x_out[i]);
    for (int i = 0; i < count; ++i) x_out[i] = Position(rho[i], h[i], x_out[i], w_max, inv_dw);
    for (int i = 0; i < count; ++i) x_out[i] = Lerp(x_table, x_out[i]);
  }

 private:
  bool valid_ = false;
  double z_ref_mm_ = 0.0;
  double w_max_ = 1.0;
  double inv_dw_ = 1.0;
  std::vector<double> x_of_w_;
  std::vector<double> viewpoint_of_w_;

  // Table position (fractional index) of the direction of (rho, h) seen from (0, z_v).
  static double Position(double rho, double h, double viewpoint_z, double w_max, double inv_dw) {
    const double dz = viewpoint_z - h;
    const double dist = std::sqrt(rho * rho + dz * dz);
    const double denom = dist + dz;
    // Points almost straight above the viewpoint (Omega -> 180 deg) map to the rim, and
    // so does anything not finite (the index must stay in the table). The division is
    // done either way: one under a condition would keep GuessMany's loop scalar.
    const double w = rho / denom;
    const bool usable = (denom > 1e-12 * dist) & (w >= 0.0) & (w <= w_max);
    return (usable ? w : w_max) * inv_dw;
  }
  static double Lerp(const double* table, double position) {
    const int i = static_cast<int>(position);
    const double t = position - i;
    return table[i] + t * (table[i + 1] - table[i]);
  }
};

}  // namespace omnical
