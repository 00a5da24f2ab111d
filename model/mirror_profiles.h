// Rotationally symmetric mirror profiles z = f(r) in the mirror frame (mm).
//
// Every profile is written as a function of s = r^2, z = g(s). A smooth surface of
// revolution is a smooth function of r^2, so g has no 0/0 at the axis and the 2-D
// (tilted) solver can use dz/dx = 2 x g'(s) everywhere. Derivatives along the radius
// follow: f' = 2 r g', f'' = 2 g' + 4 r^2 g''.
//
// Every profile has the interface listed at the top of model/model_registry.h, where
// profiles are registered (how to add one is written there).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "model/parameter_field.h"
#include "model/scalar.h"

namespace omnical {

// g(s), dg/ds and d2g/ds2 at s = r^2 (mm, 1, 1/mm^... consistent with z in mm).
template <typename S>
struct SagDerivatives {
  S z;
  S dz_ds;
  S d2z_ds2;
};

// Radial derivatives at radius r from the s-derivatives.
template <typename S>
inline void RadialSlopes(const SagDerivatives<S>& g, const S& r, S* dz_dr, S* d2z_dr2) {
  *dz_dr = S(2.0) * r * g.dz_ds;
  *d2z_dr2 = S(2.0) * g.dz_ds + S(4.0) * r * r * g.d2z_ds2;
}

// Sphere of radius of curvature A, centre on the axis at z = A:
// z = A - sqrt(A^2 - r^2). Domain: r < A.
template <typename T>
struct SphereProfile {
  static constexpr const char* kName = "sphere";
  static constexpr int kRimSlopeParam = 0;  // the one the design fit solves for
  static constexpr std::array<ParameterField, 1> kFields{
      {ScalarField("A", "A_mm", ParameterGroup::kShape, true, FieldDomain::kPositive, 1e7, 1)}};
  static constexpr int kMaxParams = 1;

  T radius_of_curvature_mm;

  int NumParams() const { return 1; }
  // Turned about its own centre a sphere is the same surface: its tilt is its gauge.
  bool TiltObservable() const { return false; }

  template <typename S>
  SagDerivatives<S> EvaluateSag(const S& r2) const {
    using std::sqrt;
    const S a(radius_of_curvature_mm);
    const S root = sqrt(a * a - r2);
    const S inv_root = S(1.0) / root;
    return {a - root, S(0.5) * inv_root, S(0.25) * inv_root * inv_root * inv_root};
  }
  std::string CheckDomain(double rim_radius_mm) const {
    const double a = ScalarPart(radius_of_curvature_mm);
    if (!(a > 0.0)) return "A (radius of curvature) must be > 0";
    if (!(rim_radius_mm < a)) return "rim_radius must be smaller than the sphere radius A";
    return {};
  }
  double MaxRadiusMm() const { return ScalarPart(radius_of_curvature_mm); }
  template <typename U>
  SphereProfile<U> Cast() const {
    return {CastScalar<U>(radius_of_curvature_mm)};
  }
  static SphereProfile FromParams(const T* params, int /*count*/ = 1) { return {params[0]}; }
  void ToParams(T* params) const { params[0] = radius_of_curvature_mm; }
  template <typename U>
  SphereProfile<U> WithParams(const U* params) const { return {params[0]}; }
  static SphereProfile FromVertexRadius(double vertex_radius_mm, double rim_mm) {
    return {T(std::max(vertex_radius_mm, 1.05 * rim_mm))};
  }
  // f'(1) = 1 / sqrt(A^2 - 1) at the normalised rim.
  template <typename U>
  static void SolveRimSlope(U* params, int /*count*/, const U& slope) {
    using std::sqrt;
    params[0] = sqrt(U(1.0) + U(1.0) / (slope * slope));
  }
};

// Even polynomial z = sum_k c_k r^(2k), k = 1..n (the seed's "equidistant" E-DI
// mirror is n = 3). Coefficients in mm^(1-2k).
template <typename T>
struct EvenPolynomialProfile {
  static constexpr const char* kName = "polynomial";
  static constexpr int kRimSlopeParam = 0;  // the one the design fit solves for
  static constexpr int kMaxCoefficients = 8;
  // c_k in mm^(1-2k): c1 per mm, c2 per mm^3, ...
  static constexpr std::array<ParameterField, 1> kFields{
      {TermList("coefficients", "c", 1, kMaxCoefficients, 1, 1, -1, -2, std::numeric_limits<double>::infinity(), true)}};
  static constexpr int kMaxParams = kMaxCoefficients;
  std::array<T, kMaxCoefficients> coefficients{};
  int num_coefficients = 0;

  int NumParams() const { return num_coefficients; }
  bool TiltObservable() const { return true; }
  template <typename S>
  SagDerivatives<S> EvaluateSag(const S& r2) const {
    // Horner on g(s) = s * (c1 + s * (c2 + ...)) with its first two derivatives.
    S p(0.0), dp(0.0), ddp(0.0);
    for (int k = num_coefficients - 1; k >= 0; --k) {
      ddp = ddp * r2 + S(2.0) * dp;
      dp = dp * r2 + p;
      p = p * r2 + S(coefficients[k]);
    }
    // g = s p, g' = p + s p', g'' = 2 p' + s p''.
    return {r2 * p, p + r2 * dp, S(2.0) * dp + r2 * ddp};
  }
  std::string CheckDomain(double /*rim_radius_mm*/) const {
    if (num_coefficients < 1 || num_coefficients > kMaxCoefficients)
      return "coefficients must list between 1 and 8 values";
    return {};
  }
  double MaxRadiusMm() const { return HUGE_VAL; }
  template <typename U>
  EvenPolynomialProfile<U> Cast() const {
    EvenPolynomialProfile<U> out;
    out.num_coefficients = num_coefficients;
    for (int k = 0; k < num_coefficients; ++k) out.coefficients[k] = CastScalar<U>(coefficients[k]);
    return out;
  }
  static EvenPolynomialProfile FromParams(const T* params, int count) {
    EvenPolynomialProfile out;
    out.num_coefficients = count;
    for (int k = 0; k < count; ++k) out.coefficients[k] = params[k];
    return out;
  }
  void ToParams(T* params) const {
    for (int k = 0; k < num_coefficients; ++k) params[k] = coefficients[k];
  }
  template <typename U>
  EvenPolynomialProfile<U> WithParams(const U* params) const {
    return EvenPolynomialProfile<U>::FromParams(params, num_coefficients);
  }
  // The parabola of that vertex radius, c1 = 1 / (2 R), and two more terms at 0.
  static EvenPolynomialProfile FromVertexRadius(double vertex_radius_mm, double /*rim_mm*/) {
    const T start[3] = {T(0.5 / vertex_radius_mm), T(0.0), T(0.0)};
    return FromParams(start, 3);
  }
  // f'(1) = sum 2k c_k, solved for c1.
  template <typename U>
  static void SolveRimSlope(U* params, int count, const U& slope) {
    U rest(0.0);
    for (int k = 1; k < count; ++k) rest += U(2.0 * (k + 1)) * params[k];
    params[0] = U(0.5) * (slope - rest);
  }
};

// Hyperboloid sheet with vertex at the origin (seed Table 1, corrected):
// z = -B + (B/A) sqrt(A^2 + r^2). Foci on the axis at z = -B +- sqrt(A^2 + B^2); a
// pinhole at the outer focus (m = B + sqrt(A^2 + B^2)) gives a single viewpoint at the
// inner one.
template <typename T>
struct HyperboloidProfile {
  static constexpr const char* kName = "hyperboloid";
  static constexpr int kRimSlopeParam = 1;  // the one the design fit solves for
  static constexpr std::array<ParameterField, 2> kFields{
      {ScalarField("A", "A_mm", ParameterGroup::kShape, true, FieldDomain::kPositive, 1e7, 1),
       ScalarField("B", "B_mm", ParameterGroup::kShape, true, FieldDomain::kPositive, 1e7, 1)}};
  static constexpr int kMaxParams = 2;
  T a_mm;
  T b_mm;

  int NumParams() const { return 2; }
  bool TiltObservable() const { return true; }

  template <typename S>
  SagDerivatives<S> EvaluateSag(const S& r2) const {
    using std::sqrt;
    const S a(a_mm), b(b_mm);
    const S root = sqrt(a * a + r2);
    const S k = b / a;
    return {k * root - b, S(0.5) * k / root, S(-0.25) * k / (root * root * root)};
  }
  std::string CheckDomain(double /*rim_radius_mm*/) const {
    if (!(ScalarPart(a_mm) > 0.0)) return "A must be > 0";
    if (!(ScalarPart(b_mm) > 0.0)) return "B must be > 0";
    return {};
  }
  double MaxRadiusMm() const { return HUGE_VAL; }
  template <typename U>
  HyperboloidProfile<U> Cast() const {
    return {CastScalar<U>(a_mm), CastScalar<U>(b_mm)};
  }
  static HyperboloidProfile FromParams(const T* params, int /*count*/ = 2) { return {params[0], params[1]}; }
  void ToParams(T* params) const {
    params[0] = a_mm;
    params[1] = b_mm;
  }
  template <typename U>
  HyperboloidProfile<U> WithParams(const U* params) const { return {params[0], params[1]}; }
  // Vertex radius of curvature A^2 / B: with A = B = R.
  static HyperboloidProfile FromVertexRadius(double vertex_radius_mm, double /*rim_mm*/) {
    return {T(vertex_radius_mm), T(vertex_radius_mm)};
  }
  // f'(1) = (B / A) / sqrt(A^2 + 1), solved for B.
  template <typename U>
  static void SolveRimSlope(U* params, int /*count*/, const U& slope) {
    using std::sqrt;
    params[1] = params[0] * sqrt(params[0] * params[0] + U(1.0)) * slope;
  }
};

// Paraboloid with its focus on the axis at z = A: z = r^2 / (4 A). Seen through an
// orthographic (telecentric) lens along its axis it has a single viewpoint, the focus.
template <typename T>
struct ParaboloidProfile {
  static constexpr const char* kName = "paraboloid";
  static constexpr int kRimSlopeParam = 0;  // the one the design fit solves for
  static constexpr std::array<ParameterField, 1> kFields{
      {ScalarField("A", "A_mm", ParameterGroup::kShape, true, FieldDomain::kPositive, 1e7, 1)}};
  static constexpr int kMaxParams = 1;
  T focal_distance_mm;

  int NumParams() const { return 1; }
  bool TiltObservable() const { return true; }

  template <typename S>
  SagDerivatives<S> EvaluateSag(const S& r2) const {
    const S inv_4a = S(0.25) / S(focal_distance_mm);
    return {r2 * inv_4a, inv_4a, S(0.0)};
  }
  std::string CheckDomain(double /*rim_radius_mm*/) const {
    if (!(ScalarPart(focal_distance_mm) > 0.0)) return "A (focal distance) must be > 0";
    return {};
  }
  double MaxRadiusMm() const { return HUGE_VAL; }
  template <typename U>
  ParaboloidProfile<U> Cast() const {
    return {CastScalar<U>(focal_distance_mm)};
  }
  static ParaboloidProfile FromParams(const T* params, int /*count*/ = 1) { return {params[0]}; }
  void ToParams(T* params) const { params[0] = focal_distance_mm; }
  template <typename U>
  ParaboloidProfile<U> WithParams(const U* params) const { return {params[0]}; }
  // Vertex radius of curvature 2 A.
  static ParaboloidProfile FromVertexRadius(double vertex_radius_mm, double /*rim_mm*/) {
    return {T(0.5 * vertex_radius_mm)};
  }
  // f'(1) = 1 / (2 A).
  template <typename U>
  static void SolveRimSlope(U* params, int /*count*/, const U& slope) {
    params[0] = U(0.5) / slope;
  }
};

}  // namespace omnical
