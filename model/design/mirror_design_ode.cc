#include "model/design/mirror_design_ode.h"

#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "model/input_error.h"

namespace omnical {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Where the log-polar law has no value (rho = 0): the integration starts this far from
// the axis with F = F0, as the seed's listing does (1e-5 cm). The law's slope vanishes
// there (h -> -infinity makes the mirror flat), so F(0) = F0 to ~1e-12 mm.
constexpr double kLogPolarStartMm = 1e-4;
constexpr double kFoldSlope = 1e3;  // |dF/dt| beyond this: the profile turns vertical

std::string At(double t_mm) {
  char text[64];
  std::snprintf(text, sizeof text, " at t = %.6g mm", t_mm);
  return text;
}

// Fritsch-Carlson slope at knot i of a strictly increasing table (harmonic mean of the
// neighbouring secants keeps each cubic monotone).
double KnotSlope(const std::vector<double>& x, const std::vector<double>& y, size_t i) {
  const size_t n = x.size();
  if (i == 0) return (y[1] - y[0]) / (x[1] - x[0]);
  if (i == n - 1) return (y[n - 1] - y[n - 2]) / (x[n - 1] - x[n - 2]);
  const double left = (y[i] - y[i - 1]) / (x[i] - x[i - 1]), right = (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
  return 2.0 / (1.0 / left + 1.0 / right);
}

// The Hermite cubic of the table's segment holding rho: value and derivative; linear
// beyond the ends.
std::array<double, 2> TableAt(const ImagingLaw& law, double rho) {
  const std::vector<double>& x = law.table_rho_mm;
  const std::vector<double>& y = law.table_h_mm;
  const size_t n = x.size();
  if (rho <= x[0]) return {y[0] + KnotSlope(x, y, 0) * (rho - x[0]), KnotSlope(x, y, 0)};
  if (rho >= x[n - 1]) return {y[n - 1] + KnotSlope(x, y, n - 1) * (rho - x[n - 1]), KnotSlope(x, y, n - 1)};
  const size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), rho) - x.begin()) - 1;
  const double width = x[i + 1] - x[i], s = (rho - x[i]) / width;
  const double m0 = KnotSlope(x, y, i) * width, m1 = KnotSlope(x, y, i + 1) * width;
  const double s2 = s * s, s3 = s2 * s;
  const double value = (2 * s3 - 3 * s2 + 1) * y[i] + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * y[i + 1] + (s3 - s2) * m1;
  const double derivative = ((6 * s2 - 6 * s) * y[i] + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * y[i + 1] + (3 * s2 - 2 * s) * m1) / width;
  return {value, derivative};
}

// Eq. 7's right-hand side dF/dt; throws InputError where the design breaks down.
double Slope(const OdeDesignSpec& spec, double t, double height) {
  const double f = spec.focal_length_mm, d = spec.distance_mm;
  if (!(height - f > 0.0)) throw InputError("design: the mirror comes down to the pinhole" + At(t));
  if (!(t < d)) throw InputError("design: the mirror reaches the reference cylinder" + At(t));
  const double rho = f * t / (height - f);
  const double h = spec.law.HeightMm(rho);
  const double numerator = t * (d - t) + (height - f) * (height - h);
  const double denominator = (height - f) * (d - t) - t * (height - h);
  // F' = -P + sqrt(P^2 + 1), P = numerator / denominator, written without cancellation.
  double slope;
  if (denominator == 0.0) {
    slope = numerator > 0.0 ? 0.0 : HUGE_VAL;
  } else {
    const double p = numerator / denominator;
    slope = p >= 0.0 ? 1.0 / (p + std::hypot(p, 1.0)) : std::hypot(p, 1.0) - p;
  }
  if (!std::isfinite(slope) || slope > kFoldSlope)
    throw InputError("design: the mirror folds back (slope dF/dt beyond 1e3)" + At(t));
  // The reflected ray must leave the axis side to reach the cylinder.
  const double ix = t, iz = height - f, in = std::hypot(ix, iz);
  const double nx = slope, nz = -1.0, nn = std::hypot(nx, nz);
  const double dot = (ix * nx + iz * nz) / (in * nn);
  const double cx = ix / in - 2.0 * dot * nx / nn;
  if (!(cx > 0.0)) throw InputError("design: the reflected ray turns back to the axis and misses the cylinder" + At(t));
  return slope;
}

using State = std::array<double, 1>;

}  // namespace

double ImagingLaw::HeightMm(double rho_mm) const {
  switch (kind) {
    case Kind::kLinear:
      return gain * rho_mm + offset_mm;
    case Kind::kLogPolar:
      return gain * std::log(rho_mm / rho0_mm) / std::log(growth_rate) + offset_mm;
    case Kind::kTable:
      return TableAt(*this, rho_mm)[0];
  }
  return NAN;
}

double ImagingLaw::SlopePerRho(double rho_mm) const {
  switch (kind) {
    case Kind::kLinear:
      return gain;
    case Kind::kLogPolar:
      return gain / (std::log(growth_rate) * rho_mm);
    case Kind::kTable:
      return TableAt(*this, rho_mm)[1];
  }
  return NAN;
}

std::string ImagingLaw::Check(double rho0_mm_used, double rho1_mm) const {
  switch (kind) {
    case Kind::kLinear:
      if (!(gain > 0.0) || !std::isfinite(gain)) return "law.gain: must be positive (h must grow with rho)";
      if (!std::isfinite(offset_mm)) return "law.offset_mm: not a finite number";
      return {};
    case Kind::kLogPolar:
      if (!(gain > 0.0) || !std::isfinite(gain)) return "law.gain_mm: must be positive (h must grow with rho)";
      if (!(growth_rate > 1.0) || !std::isfinite(growth_rate)) return "law.growth_rate: must be > 1";
      if (!(rho0_mm > 0.0) || !std::isfinite(rho0_mm)) return "imager.rho0_mm: the log-polar law needs rho0 > 0";
      if (!std::isfinite(offset_mm)) return "law.offset_mm: not a finite number";
      return {};
    case Kind::kTable: {
      const std::string where = "law.table" + (table_source.empty() ? "" : " (" + table_source + ")");
      if (table_rho_mm.size() < 2 || table_rho_mm.size() != table_h_mm.size()) return where + ": needs at least 2 rows of rho_mm, h_mm";
      for (size_t i = 1; i < table_rho_mm.size(); ++i) {
        if (!(table_rho_mm[i] > table_rho_mm[i - 1])) return where + ": rho is not increasing at row " + std::to_string(i + 1);
        if (!(table_h_mm[i] > table_h_mm[i - 1]))
          return where + ": the law is not monotone (h does not increase) at row " + std::to_string(i + 1);
      }
      if (rho0_mm_used < table_rho_mm.front()) return where + ": rho0 lies before the table's first rho";
      if (rho1_mm > table_rho_mm.back()) return where + ": rho1 lies beyond the table's last rho";
      return {};
    }
  }
  return "law: unknown kind";
}

std::string OdeDesignSpec::Check() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(focal_length_mm)) return "focal_length_mm: must be positive";
  if (!positive(distance_mm)) return "distance_mm: must be positive";
  if (!positive(rim_limit_mm)) return "rim_limit_mm: must be positive";
  if (!std::isfinite(start_height_mm) || !(start_height_mm > focal_length_mm))
    return "start_height_mm: the mirror vertex must lie above the pinhole (F0 > f)";
  if (!(rim_limit_mm < distance_mm)) return "rim_limit_mm: the mirror must end inside the reference cylinder";
  if (!std::isfinite(rho0_mm) || rho0_mm < 0.0) return "imager.rho0_mm: must be >= 0";
  if (!positive(rho1_mm) || !(rho1_mm > rho0_mm)) return "imager.rho1_mm: must be > rho0";
  return law.Check(rho0_mm, rho1_mm);
}

double ReflectedSlope(double t, double height, double slope, double f) {
  return (2.0 * t * slope - (height - f) * (1.0 - slope * slope)) / (2.0 * (height - f) * slope + t * (1.0 - slope * slope));
}

double ElevationDeg(double reflected_slope) { return std::atan2(1.0, -reflected_slope) * 180.0 / kPi; }

OdeDesign SolveMirrorOde(const OdeDesignSpec& spec, int samples) {
  if (const std::string why = spec.Check(); !why.empty()) throw InputError("design: " + why);
  namespace odeint = boost::numeric::odeint;
  const double f = spec.focal_length_mm;
  auto rhs = [&](const State& x, State& dxdt, double t) { dxdt[0] = Slope(spec, t, x[0]); };
  auto rho_of = [&](double t, double height) { return f * t / (height - f); };
  const double t_first = std::isfinite(spec.law.HeightMm(0.0)) ? 0.0 : kLogPolarStartMm;
  constexpr double kTolerance = 1e-13;
  auto make_stepper = [] { return odeint::make_dense_output(kTolerance, kTolerance, odeint::runge_kutta_dopri5<State>()); };

  // Pass 1: to the rim, or to where rho reaches rho1 (bisection on the dense output).
  OdeDesign design;
  auto stepper = make_stepper();
  stepper.initialize(State{spec.start_height_mm}, t_first, 1e-3);
  double t_end = spec.rim_limit_mm;
  bool reached_rho1 = false;
  while (stepper.current_time() < spec.rim_limit_mm) {
    stepper.do_step(rhs);
    ++design.ode_steps;
    const double t_now = std::min(stepper.current_time(), spec.rim_limit_mm);
    State x;
    stepper.calc_state(t_now, x);
    if (rho_of(t_now, x[0]) >= spec.rho1_mm) {
      double lo = stepper.previous_time(), hi = t_now;
      for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
        const double mid = 0.5 * (lo + hi);
        stepper.calc_state(mid, x);
        (rho_of(mid, x[0]) < spec.rho1_mm ? lo : hi) = mid;
      }
      t_end = hi;
      reached_rho1 = true;
      break;
    }
  }
  if (!reached_rho1) {
    State x;
    stepper.calc_state(spec.rim_limit_mm, x);
    const double rho_rim = rho_of(spec.rim_limit_mm, x[0]);
    if (rho_rim < 0.95 * spec.rho1_mm) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "design: imager.rho1_mm = %g is beyond the image of the rim (rho = %.6g mm at t1 = %g mm); "
                    "enlarge rim_limit_mm or reduce rho1",
                    spec.rho1_mm, rho_rim, spec.rim_limit_mm);
      throw InputError(text);
    }
    design.ended_at_rim = true;
  }

  // Pass 2: the profile on a uniform grid of t, from a fresh integration.
  std::vector<double> grid(samples);
  for (int i = 0; i < samples; ++i) grid[i] = t_first + (t_end - t_first) * i / (samples - 1);
  State x{spec.start_height_mm};
  odeint::integrate_times(make_stepper(), rhs, x, grid.begin(), grid.end(), 1e-3, [&](const State& state, double t) {
    design.profile.push_back({t, state[0], Slope(spec, t, state[0])});
  });
  if (t_first > 0.0) design.profile.front().radius_mm = 0.0;  // the vertex (see kLogPolarStartMm)
  const ProfileSample& last = design.profile.back();
  design.t_end_mm = last.radius_mm;
  design.rho_end_mm = rho_of(last.radius_mm, last.height_mm);
  design.phi1_deg = ElevationDeg(ReflectedSlope(last.radius_mm, last.height_mm, last.slope, f));

  // rho0's mirror radius: bisection on the profile's own ODE from the nearest sample.
  if (spec.rho0_mm <= rho_of(design.profile.front().radius_mm, design.profile.front().height_mm)) {
    const ProfileSample& first = design.profile.front();
    design.t_start_mm = first.radius_mm;
    design.phi0_deg = ElevationDeg(ReflectedSlope(std::max(first.radius_mm, t_first), first.height_mm, first.slope, f));
  } else {
    size_t i = 1;
    while (i < design.profile.size() && rho_of(design.profile[i].radius_mm, design.profile[i].height_mm) < spec.rho0_mm) ++i;
    if (i == design.profile.size()) throw InputError("design: imager.rho0_mm lies beyond the image of the mirror");
    double lo = design.profile[i - 1].radius_mm, hi = design.profile[i].radius_mm;
    State at;
    for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; ++k) {
      const double mid = 0.5 * (lo + hi);
      at = {design.profile[i - 1].height_mm};
      odeint::integrate_adaptive(make_stepper(), rhs, at, design.profile[i - 1].radius_mm, mid, 1e-4);
      (rho_of(mid, at[0]) < spec.rho0_mm ? lo : hi) = mid;
    }
    at = {design.profile[i - 1].height_mm};
    odeint::integrate_adaptive(make_stepper(), rhs, at, design.profile[i - 1].radius_mm, hi, 1e-4);
    design.t_start_mm = hi;
    design.phi0_deg = ElevationDeg(ReflectedSlope(hi, at[0], Slope(spec, hi, at[0]), f));
  }
  return design;
}

}  // namespace omnical
