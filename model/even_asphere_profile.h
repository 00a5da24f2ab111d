// The even asphere of optical design programs and ISO 10110 drawings, in the mirror frame:
//   z = c r^2 / (1 + sqrt(1 - (1 + k) c^2 r^2)) + a4 r^4 + a6 r^6 + ... ,  c = 1 / R,
// with R the vertex radius of curvature (mm), k the conic constant and up to 8 even terms
// a4 .. a18 (mm^-3, mm^-5, ...). The conic alone is the sphere (k = 0, R = A), the
// paraboloid (k = -1, R = 2 A), a hyperboloid (k < -1: R = A^2 / B, k = -1 - A^2 / B^2
// for HyperboloidProfile's A, B) or an ellipsoid (-1 < k < 0; k > 0 an oblate one). A
// mirror bought from a catalogue comes with exactly these numbers.
//
// In s = r^2, with q = (1 + k) c^2 and w = sqrt(1 - q s):
//   g = c s / (1 + w) + sum_i a_2i s^i,  g' = c / (2 w) + ...,  g'' = c q / (4 w^3) + ...
// (c s / (1 + w) rather than (1 - w) / ((1 + k) c): no cancellation near the axis and no
// 0/0 at k = -1). Domain: q s < 1, i.e. r < R / sqrt(1 + k) when 1 + k > 0 (where the
// conic's slope becomes vertical); everywhere otherwise. Only convex mirrors (R > 0) are
// modelled, as for every other profile.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "model/mirror_profiles.h"
#include "model/parameter_field.h"
#include "model/scalar.h"

namespace omnical {

template <typename T>
struct EvenAsphereProfile {
  static constexpr const char* kName = "even_asphere";
  static constexpr int kMaxTerms = 8;
  static constexpr std::array<ParameterField, 3> kFields{
      {ScalarField("R", "R_mm", ParameterGroup::kShape, true, FieldDomain::kPositive, 1e7, 1),
       ScalarField("k", "k", ParameterGroup::kShape, false, FieldDomain::kBounded, 1e6, 0),
       TermList("a", "a", 0, kMaxTerms, 4, 2, -3, -2, std::numeric_limits<double>::infinity(), false)}};
  static constexpr int kMaxParams = 2 + kMaxTerms;
  static constexpr int kRimSlopeParam = 0;  // R, from k and the terms

  T vertex_radius_mm;
  T conic_constant;
  std::array<T, kMaxTerms> terms{};  // a4, a6, ...
  int num_terms = 0;

  int NumParams() const { return 2 + num_terms; }
  // With k near 0 and no terms it is a sphere, whose tilt about its centre changes nothing
  // (1e-3: the fitted k of a sphere's images, 0.009 +- 0.012 on a rendered set, is then
  // held at the start's 0 by the tilt's gauge; a real conic is far from it).
  bool TiltObservable() const { return num_terms > 0 || std::abs(ScalarPart(conic_constant)) >= 1e-3; }

  template <typename S>
  SagDerivatives<S> EvaluateSag(const S& r2) const {
    using std::sqrt;
    const S c = S(1.0) / S(vertex_radius_mm);
    const S q = (S(1.0) + S(conic_constant)) * c * c;
    const S w = sqrt(S(1.0) - q * r2);
    // The terms as s^2 p(s), p(s) = a4 + a6 s + ..., by Horner with two derivatives.
    S p(0.0), dp(0.0), ddp(0.0);
    for (int k = num_terms - 1; k >= 0; --k) {
      ddp = ddp * r2 + S(2.0) * dp;
      dp = dp * r2 + p;
      p = p * r2 + S(terms[k]);
    }
    return {c * r2 / (S(1.0) + w) + r2 * r2 * p, c / (S(2.0) * w) + S(2.0) * r2 * p + r2 * r2 * dp,
            c * q / (S(4.0) * w * w * w) + S(2.0) * p + S(4.0) * r2 * dp + r2 * r2 * ddp};
  }

  std::string CheckDomain(double rim_radius_mm) const {
    const double radius = ScalarPart(vertex_radius_mm);
    if (!(radius > 0.0) || !std::isfinite(radius)) return "R (vertex radius of curvature) must be > 0";
    if (!std::isfinite(ScalarPart(conic_constant))) return "k (conic constant) must be finite";
    if (num_terms < 0 || num_terms > kMaxTerms) return "a must list at most 8 even terms (a4 .. a18)";
    if (!(rim_radius_mm < MaxRadiusMm()))
      return "rim_radius must be smaller than R / sqrt(1 + k), where the conic's slope becomes vertical";
    return {};
  }
  double MaxRadiusMm() const {
    const double one_plus_k = 1.0 + ScalarPart(conic_constant);
    return one_plus_k > 0.0 ? ScalarPart(vertex_radius_mm) / std::sqrt(one_plus_k) : HUGE_VAL;
  }

  template <typename U>
  EvenAsphereProfile<U> Cast() const {
    EvenAsphereProfile<U> out{CastScalar<U>(vertex_radius_mm), CastScalar<U>(conic_constant)};
    out.num_terms = num_terms;
    for (int k = 0; k < num_terms; ++k) out.terms[k] = CastScalar<U>(terms[k]);
    return out;
  }
  // R, k, a4, a6, ...
  static EvenAsphereProfile FromParams(const T* params, int count) {
    EvenAsphereProfile out{params[0], params[1]};
    out.num_terms = std::max(0, count - 2);
    for (int k = 0; k < out.num_terms; ++k) out.terms[k] = params[2 + k];
    return out;
  }
  void ToParams(T* params) const {
    params[0] = vertex_radius_mm;
    params[1] = conic_constant;
    for (int k = 0; k < num_terms; ++k) params[2 + k] = terms[k];
  }
  template <typename U>
  EvenAsphereProfile<U> WithParams(const U* params) const {
    return EvenAsphereProfile<U>::FromParams(params, NumParams());
  }
  // The paraboloid of that vertex radius (k = -1): defined at every radius, unlike the
  // sphere, whose surface ends at R.
  static EvenAsphereProfile FromVertexRadius(double vertex_radius_mm, double /*rim_mm*/) {
    return {T(vertex_radius_mm), T(-1.0)};
  }
  // f'(1) = c / sqrt(1 - (1 + k) c^2) + sum 2i a_2i = slope: with S = slope - sum,
  // c = S / sqrt(1 + (1 + k) S^2).
  template <typename U>
  static void SolveRimSlope(U* params, int count, const U& slope) {
    using std::sqrt;
    U rest(0.0);
    for (int k = 2; k < count; ++k) rest += U(2.0 * k) * params[k];
    const U conic_slope = slope - rest;
    params[0] = sqrt(U(1.0) + (U(1.0) + params[1]) * conic_slope * conic_slope) / conic_slope;
  }
};

}  // namespace omnical
