#include "model/tabulated_profile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>


namespace omnical {

ProfileSpline::ProfileSpline(std::vector<double> radius_mm, std::vector<double> sag_mm, double end_slope_dz_dr,
                             double vertex_slope_dz_dr)
    : radius_mm_(std::move(radius_mm)), sag_(std::move(sag_mm)) {
  const size_t n = radius_mm_.size();
  if (n < 4 || sag_.size() != n)
    throw std::invalid_argument("a profile table needs at least 4 (r, z) rows");
  if (radius_mm_[0] != 0.0 || sag_[0] != 0.0)
    throw std::invalid_argument("the first row must be the vertex, r = 0 and z = 0");
  for (size_t i = 1; i < n; ++i)
    if (!(radius_mm_[i] > radius_mm_[i - 1]))
      throw std::invalid_argument("r must increase strictly (row " + std::to_string(i + 1) + ")");
  if (!std::isfinite(vertex_slope_dz_dr)) throw std::invalid_argument("the vertex slope dz/dr must be finite");
  cone_tip_ = vertex_slope_dz_dr != 0.0;
  knots_.resize(n);
  for (size_t i = 0; i < n; ++i) knots_[i] = cone_tip_ ? radius_mm_[i] : radius_mm_[i] * radius_mm_[i];
  max_radius_mm_ = radius_mm_.back();
  r2_last_ = max_radius_mm_ * max_radius_mm_;
  cone_floor_r2_ = 1e-18 * r2_last_;

  // Second derivatives at the knots: natural (zero) at an end, or clamped to a slope there
  // (the vertex of a cone point: its slope; the rim: the table's). Thomas algorithm on the
  // tridiagonal system (diagonally dominant, so no pivoting is needed).
  const bool clamped_end = std::isfinite(end_slope_dz_dr);
  // Slopes in the knot variable: dz/ds = (dz/dr) / (2 r) for knots in r^2.
  const double end_slope_k = cone_tip_ ? end_slope_dz_dr : end_slope_dz_dr / (2.0 * max_radius_mm_);
  const size_t first = cone_tip_ ? 0 : 1, last = clamped_end ? n - 1 : n - 2;
  second_.assign(n, 0.0);
  std::vector<double> diag(n, 0.0), rhs(n, 0.0), upper(n, 0.0), lower(n, 0.0);
  auto step = [&](size_t i) { return knots_[i + 1] - knots_[i]; };
  auto divided = [&](size_t i) { return (sag_[i + 1] - sag_[i]) / step(i); };
  for (size_t i = first; i <= last; ++i) {
    if (i == 0) {  // clamped vertex (cone point)
      diag[i] = step(0) / 3.0;
      upper[i] = step(0) / 6.0;
      rhs[i] = divided(0) - vertex_slope_dz_dr;
    } else if (i + 1 < n) {
      lower[i] = step(i - 1) / 6.0;
      diag[i] = (step(i - 1) + step(i)) / 3.0;
      upper[i] = step(i) / 6.0;
      rhs[i] = divided(i) - divided(i - 1);
    } else {  // clamped end
      lower[i] = step(i - 1) / 6.0;
      diag[i] = step(i - 1) / 3.0;
      rhs[i] = end_slope_k - divided(i - 1);
    }
    if (i > first) {
      const double w = lower[i] / diag[i - 1];
      diag[i] -= w * upper[i - 1];
      rhs[i] -= w * rhs[i - 1];
    }
  }
  for (size_t i = last + 1; i-- > first;) second_[i] = (rhs[i] - (i + 1 <= last ? upper[i] * second_[i + 1] : 0.0)) / diag[i];
  const double h = step(n - 2);
  const double end_dz_dk = divided(n - 2) + h * (second_[n - 2] + 2.0 * second_[n - 1]) / 6.0;
  end_slope_ = cone_tip_ ? end_dz_dk / (2.0 * max_radius_mm_) : end_dz_dk;
}

int ProfileSpline::Segment(double knot_variable) const {
  const auto it = std::upper_bound(knots_.begin(), knots_.end(), knot_variable);
  const int index = static_cast<int>(it - knots_.begin()) - 1;
  return std::clamp(index, 0, static_cast<int>(knots_.size()) - 2);
}

}  // namespace omnical
