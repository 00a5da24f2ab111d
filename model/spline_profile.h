// A free-form mirror for the bundle fit to shape: a paraboloid plus a uniform cubic
// B-spline in s = r^2,
//   g(s) = c1 s + B(s),  B(s) = sum_j v_j N_j(s),  N_j(s) = N((s - j h) / h),
// N the cardinal cubic B-spline (support [-2, 2]), h = span^2 / (n - 1) for n control
// values v_1 .. v_n ("knots" in the sensor file, mm). The n knot positions 0, h, ..,
// span^2 bound the n - 1 segments; v_n sits one spacing beyond the span (each segment
// uses 4 values). Being a function of s the surface is even in r and smooth across the
// axis by construction.
//
// The axis: two phantom values v_0 = -v_1 / 2 and v_-1 = v_1 make B(0) = 0 and B'(0) = 0
// (B(0) = (v_-1 + 4 v_0 + v_1) / 6, B'(0) = (v_1 - v_-1) / 2h). Without them a constant
// in B would trade exactly with m and a linear one with c1 (B-splines reproduce both):
// two directions the fit could not determine. So c1 = g'(0) is the vertex curvature
// (R = 1 / (2 c1)), the knots the departure from that paraboloid, B''(0) = 3 v_1 / h^2.
// The space is every C2 cubic spline on these knots with g(0) = 0: n + 1 parameters,
// none redundant.
//
// Beyond the span: the end's quadratic in s, g(S) + g'(S) d + g''(S) d^2 / 2: C2 at the
// span end as at every knot (only g''' jumps), so solvers iterating past the rim see a
// smooth surface, growing no faster than the paraboloid's r^4 (the end cubic would).
// C2 is what the solvers need; the surface normal is then C1, and so is the image
// mapping across a knot's circle (its second derivative jumps with g'''): a strong
// wiggle in the knots bends it faster than an interpolating remap grid expects
// (tests/test_sensors.h).
//
// The span is not a parameter but a setting (model/model_registry.h, kSettings): it is
// where the knots are, a choice rather than a measurement, and a fit moving it would
// re-mean every knot value. It cannot be the sensor's rim_radius either: the fit sets
// the rim to the widest reflection point it saw (calib/bundle_fit.cc), which would move
// the knots under a saved spline. FromVertexRadius takes the rim as the span, so a
// spline converted from another guess covers exactly the mirror.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "model/mirror_profiles.h"
#include "model/parameter_field.h"
#include "model/scalar.h"

namespace omnical {

template <typename T>
struct SplineProfile {
  static constexpr const char* kName = "spline";
  static constexpr int kMinKnots = 4;  // 3 segments: fewer add little to the polynomial
  static constexpr int kMaxKnots = 16;
  // FromVertexRadius (a converted guess): 6 holds the steep Ohte sphere to 2e-3 mm of sag
  // and fits its renders as the sphere does (0.053 px); on the real Mei set 8 and 12 left
  // directions the 10 views barely see (the centre shows the camera).
  static constexpr int kDefaultKnots = 6;
  static constexpr std::array<ParameterField, 2> kFields{
      {ScalarField("c1", "c1", ParameterGroup::kShape, true, FieldDomain::kPositive, 1e6, -1),
       TermList("knots", "knot", kMinKnots, kMaxKnots, 1, 1, 1, 0, 1e5, false)}};
  static constexpr std::array<ParameterField, 1> kSettings{
      {ScalarField("span", "span_mm", ParameterGroup::kShape, false, FieldDomain::kPositive, 1e5, 1)}};
  static constexpr int kMaxParams = 1 + kMaxKnots;
  static constexpr int kRimSlopeParam = -1;  // not a design family: its shape is fitted, not designed

  double span_mm = 0.0;  // the radius of the last knot position (a setting, never fitted)
  T c1_per_mm{};
  std::array<T, kMaxKnots> knots_mm{};  // v_1 .. v_n
  int num_knots = 0;

  int NumParams() const { return 1 + num_knots; }
  bool TiltObservable() const { return true; }

  // The knot spacing in s (mm^2).
  double SpacingMm2() const { return span_mm * span_mm / (num_knots - 1); }

  template <typename S>
  SagDerivatives<S> EvaluateSag(const S& r2) const {
    const double h = SpacingMm2();
    const double end_s = span_mm * span_mm;
    const S c1(c1_per_mm);
    if (ScalarPart(r2) > end_s) {
      const SagDerivatives<S> end = Segment<S>(num_knots - 2, S(1.0), h);
      const S d = r2 - S(end_s);
      return {c1 * r2 + end.z + d * (end.dz_ds + S(0.5) * d * end.d2z_ds2), c1 + end.dz_ds + d * end.d2z_ds2,
              end.d2z_ds2};
    }
    // Clamped before the conversion: a NaN or huge r^2 (the batch solver's iterates for a
    // point it will reject) must not reach static_cast<int>, which is undefined there.
    const double segment = std::floor(ScalarPart(r2) / h);
    const int i = segment > 0.0 ? static_cast<int>(std::min(segment, static_cast<double>(num_knots - 2))) : 0;
    const SagDerivatives<S> b = Segment<S>(i, (r2 - S(i * h)) / S(h), h);
    return {c1 * r2 + b.z, c1 + b.dz_ds, b.d2z_ds2};
  }

  std::string CheckDomain(double rim_radius_mm) const {
    if (!(span_mm > 0.0) || !std::isfinite(span_mm))
      return "span: must be > 0 mm (the radius the knots cover, usually the rim's)";
    if (!(ScalarPart(c1_per_mm) > 0.0) || !std::isfinite(ScalarPart(c1_per_mm)))
      return "c1: must be > 0 (the vertex curvature 1 / (2 R), per mm)";
    if (num_knots < kMinKnots || num_knots > kMaxKnots) return "knots: must list between 4 and 16 values";
    for (int k = 0; k < num_knots; ++k)
      if (!std::isfinite(ScalarPart(knots_mm[k]))) return "knots: must be finite";
    return CheckConvex(rim_radius_mm);
  }
  double MaxRadiusMm() const { return HUGE_VAL; }  // the end quadratic extrapolates

  template <typename U>
  SplineProfile<U> Cast() const {
    SplineProfile<U> out;
    out.span_mm = span_mm;
    out.c1_per_mm = CastScalar<U>(c1_per_mm);
    out.num_knots = num_knots;
    for (int k = 0; k < num_knots; ++k) out.knots_mm[k] = CastScalar<U>(knots_mm[k]);
    return out;
  }
  // c1, v_1 .. v_n. The span is not among them: SetSettings, or WithParams on a spline that has it.
  static SplineProfile FromParams(const T* params, int count) {
    SplineProfile out;
    out.c1_per_mm = params[0];
    out.num_knots = std::clamp(count - 1, 0, kMaxKnots);
    for (int k = 0; k < out.num_knots; ++k) out.knots_mm[k] = params[1 + k];
    return out;
  }
  void ToParams(T* params) const {
    params[0] = c1_per_mm;
    for (int k = 0; k < num_knots; ++k) params[1 + k] = knots_mm[k];
  }
  template <typename U>
  SplineProfile<U> WithParams(const U* params) const {
    SplineProfile<U> out = SplineProfile<U>::FromParams(params, NumParams());
    out.span_mm = span_mm;
    return out;
  }
  void ToSettings(double* values) const { values[0] = span_mm; }
  void SetSettings(const double* values) { span_mm = values[0]; }

  // The paraboloid of that vertex radius (all knots 0) over the rim.
  static SplineProfile FromVertexRadius(double vertex_radius_mm, double rim_mm) {
    SplineProfile out;
    out.span_mm = rim_mm;
    out.c1_per_mm = T(0.5 / vertex_radius_mm);
    out.num_knots = kDefaultKnots;
    for (int k = 0; k < kDefaultKnots; ++k) out.knots_mm[k] = T(0.0);
    return out;
  }

  // The bundle fit's smoothness prior on the knots (calib/shape_smoothness.h), one value per
  // knot position s_j, j = 0 .. n - 1: the second difference v_j-1 - 2 v_j + v_j+1 (the
  // phantoms included) is h^2 B''(s_j), and 4 S B'' the radial curvature z'' the knots add
  // at the span S = span^2; as a ratio to the vertex's 2 c1 (this spline's c1: the guess's,
  // so the prior stays quadratic), 2 S B''(s_j) / c1. Scale-free, and 0 for the paraboloid.
  int NumSmoothnessResiduals() const { return num_knots; }
  template <typename U>
  void SmoothnessResiduals(const U* params, U* residuals) const {
    const double h = SpacingMm2();
    const double scale = 2.0 * span_mm * span_mm / (h * h * ScalarPart(c1_per_mm));
    const SplineProfile<U> shape = WithParams<U>(params);
    for (int j = 0; j < num_knots; ++j)
      residuals[j] = U(scale) * (shape.template Control<U>(j - 1) - U(2.0) * shape.template Control<U>(j) +
                                 shape.template Control<U>(j + 1));
  }

  // v_j for j = -1 .. n (the two phantoms at the axis, see the top).
  template <typename S>
  S Control(int j) const {
    if (j >= 1) return S(knots_mm[j - 1]);
    return j == 0 ? S(-0.5) * S(knots_mm[0]) : S(knots_mm[0]);
  }

 private:
  // B and its s-derivatives on segment i ([i h, (i + 1) h]) at t = (s - i h) / h, from
  // v_i-1 .. v_i+2 and the uniform cubic B-spline's four pieces.
  template <typename S>
  SagDerivatives<S> Segment(int i, const S& t, double h) const {
    const S v0 = Control<S>(i - 1), v1 = Control<S>(i), v2 = Control<S>(i + 1), v3 = Control<S>(i + 2);
    const S u = S(1.0) - t;
    const S t2 = t * t;
    const S z = (u * u * u * v0 + (S(3.0) * t2 * t - S(6.0) * t2 + S(4.0)) * v1 +
                 (S(-3.0) * t2 * t + S(3.0) * t2 + S(3.0) * t + S(1.0)) * v2 + t2 * t * v3) /
                S(6.0);
    const S dz_dt = (-(u * u) * v0 + (S(3.0) * t2 - S(4.0) * t) * v1 + (S(-3.0) * t2 + S(2.0) * t + S(1.0)) * v2 +
                     t2 * v3) /
                    S(2.0);
    const S d2z_dt2 = u * v0 + (S(3.0) * t - S(2.0)) * v1 + (S(1.0) - S(3.0) * t) * v2 + t * v3;
    return {z, dz_dt / S(h), d2z_dt2 / S(h * h)};
  }

  // z' > 0 and z'' > 0 out to the rim, exactly: on each segment (and beyond the span) g'
  // and r z'' / r = 2 g' + 4 s g'' are quadratics in s, so their minima are found from
  // three values. The sensor check (ValidateSensorModel) samples the same; this one
  // names the knots.
  std::string CheckConvex(double rim_radius_mm) const {
    const double h = SpacingMm2(), end_s = span_mm * span_mm, rim_s = rim_radius_mm * rim_radius_mm;
    auto quantities = [&](double s) {
      const SagDerivatives<double> g = Cast<double>().EvaluateSag(s);
      return std::array<double, 2>{g.dz_ds, 2.0 * g.dz_ds + 4.0 * s * g.d2z_ds2};
    };
    // The pieces: the n - 1 segments, then the end quadratic, as far as the rim.
    for (int i = 0; i < num_knots; ++i) {
      const double a = i * h;
      const double b = std::min(i + 2 < num_knots ? (i + 1) * h : i + 1 < num_knots ? end_s : rim_s, rim_s);
      if (!(a < b)) continue;
      const std::array<double, 2> qa = quantities(a), qm = quantities(0.5 * (a + b)), qb = quantities(b);
      for (int k = 0; k < 2; ++k) {
        // q(t) = alpha t^2 + beta t + qa on t in [0, 1].
        const double alpha = 2.0 * qa[k] - 4.0 * qm[k] + 2.0 * qb[k], beta = qb[k] - qa[k] - alpha;
        double t_min = qa[k] < qb[k] ? 0.0 : 1.0;
        if (alpha > 0.0 && beta < 0.0 && -beta < 2.0 * alpha) t_min = -beta / (2.0 * alpha);
        if (!(alpha * t_min * t_min + beta * t_min + qa[k] > 0.0)) {
          char text[200];
          std::snprintf(text, sizeof text,
                        "knots: the profile is not convex towards the camera at r = %.4g mm (z'%s <= 0): the knots "
                        "bend it more than a mirror can bend",
                        std::sqrt(a + t_min * (b - a)), k == 0 ? "" : "'");
          return text;
        }
      }
    }
    return {};
  }
};

}  // namespace omnical
