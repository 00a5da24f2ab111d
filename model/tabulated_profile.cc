#include "model/tabulated_profile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "model/csv_reader.h"
#include "model/input_error.h"

namespace omnical {

CubicSplineInR2::CubicSplineInR2(std::vector<double> radius_mm, std::vector<double> sag_mm, double end_slope_dz_dr)
    : radius_mm_(std::move(radius_mm)), sag_(std::move(sag_mm)) {
  const size_t n = radius_mm_.size();
  if (n < 4 || sag_.size() != n)
    throw std::invalid_argument("a profile table needs at least 4 (r, z) rows");
  if (radius_mm_[0] != 0.0 || sag_[0] != 0.0)
    throw std::invalid_argument("the first row must be the vertex, r = 0 and z = 0");
  for (size_t i = 1; i < n; ++i)
    if (!(radius_mm_[i] > radius_mm_[i - 1]))
      throw std::invalid_argument("r must increase strictly (row " + std::to_string(i + 1) + ")");
  r2_.resize(n);
  for (size_t i = 0; i < n; ++i) r2_[i] = radius_mm_[i] * radius_mm_[i];
  max_radius_mm_ = radius_mm_.back();

  // Natural spline (second derivatives zero at both ends), or clamped to a given slope at
  // the last knot; Thomas algorithm on the tridiagonal system (strictly diagonally
  // dominant, so no pivoting is needed).
  const bool clamped = std::isfinite(end_slope_dz_dr);
  const size_t last = clamped ? n - 1 : n - 2;  // the last unknown second derivative
  second_.assign(n, 0.0);
  std::vector<double> diag(n, 0.0), rhs(n, 0.0), upper(n, 0.0);
  for (size_t i = 1; i <= last; ++i) {
    const double h0 = r2_[i] - r2_[i - 1];
    const double lower = h0 / 6.0;
    if (i + 1 < n) {
      const double h1 = r2_[i + 1] - r2_[i];
      diag[i] = (h0 + h1) / 3.0;
      upper[i] = h1 / 6.0;
      rhs[i] = (sag_[i + 1] - sag_[i]) / h1 - (sag_[i] - sag_[i - 1]) / h0;
    } else {  // clamped end: dz/ds = (dz/dr) / (2 r)
      diag[i] = h0 / 3.0;
      rhs[i] = end_slope_dz_dr / (2.0 * radius_mm_[i]) - (sag_[i] - sag_[i - 1]) / h0;
    }
    if (i > 1) {
      const double w = lower / diag[i - 1];
      diag[i] -= w * upper[i - 1];
      rhs[i] -= w * rhs[i - 1];
    }
  }
  for (size_t i = last; i >= 1; --i) {
    second_[i] = (rhs[i] - (i + 1 < n ? upper[i] * second_[i + 1] : 0.0)) / diag[i];
    if (i == 1) break;
  }
  const double h = r2_[n - 1] - r2_[n - 2];
  end_slope_ = (sag_[n - 1] - sag_[n - 2]) / h + h * (second_[n - 2] + 2.0 * second_[n - 1]) / 6.0;
}

int CubicSplineInR2::Segment(double r2) const {
  const auto it = std::upper_bound(r2_.begin(), r2_.end(), r2);
  const int index = static_cast<int>(it - r2_.begin()) - 1;
  return std::clamp(index, 0, static_cast<int>(r2_.size()) - 2);
}

std::shared_ptr<const CubicSplineInR2> LoadProfileTable(const std::string& path) {
  const CsvTable table = ReadNumericCsv(path, 2);
  std::vector<double> radius, sag;
  bool slopes = true;
  for (const auto& row : table.rows) {
    radius.push_back(row[0]);
    sag.push_back(row[1]);
    slopes = slopes && row.size() >= 3;
  }
  try {
    const double end_slope = slopes ? table.rows.back()[2] : NAN;
    return std::make_shared<const CubicSplineInR2>(std::move(radius), std::move(sag), end_slope);
  } catch (const std::invalid_argument& error) {
    throw InputError(InputMessage(path, "", error.what()));
  }
}

}  // namespace omnical
