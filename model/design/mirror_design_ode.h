// Mirror design by the reflection ODE of Gächter (CTU-CMP-2001-03, Sec. 3, Eq. 7): a
// rotationally symmetric mirror F(t) above a pinhole camera such that the image radius
// rho of a point of a cylinder of radius d follows a chosen imaging law h(rho).
//
// Gächter's frame (a vertical cross-section, all mm here; the listings use cm): the image
// plane is z = 0, the pinhole at z = f on the axis, the mirror point at radius t has height
// F(t); the ray through image radius rho meets it where rho = f t / (F - f) (Eq. 9). A
// world point (d, h) is on the reference cylinder; the reflected ray's slope
// C = dz/drho is Eq. 6's fraction, so h(t) = F + C (d - t). Elevation phi is measured from
// the -z axis (the direction the camera looks away from), as the seed's Omega.
//
// The ODE is integrated with Boost.Odeint's Dormand-Prince 5(4) (adaptive, dense output)
// to 1e-13 relative; the profile is then sampled from the dense output with its slope
// from the ODE's right-hand side. In omnical's sensor frame the mirror vertex is the
// origin and the lens m = F0 - f below it; sag z(x) = F(x) - F(0).
#pragma once

#include <string>
#include <vector>

namespace omnical {

// h(rho): the height (mm, Gächter's frame) on the reference cylinder that image radius
// rho (mm) must see. Strictly increasing over the imager.
struct ImagingLaw {
  enum class Kind { kLinear, kLogPolar, kTable } kind = Kind::kLinear;
  double gain = 0.0;       // linear: a (dimensionless); log-polar: a (mm)
  double offset_mm = 0.0;  // b
  double rho0_mm = 0.0;    // log-polar: innermost circle of the layout
  double growth_rate = 0.0;  // log-polar: k > 1
  std::vector<double> table_rho_mm, table_h_mm;  // table: monotone cubic (Fritsch-Carlson)
  std::string table_source;  // the table's file, for messages

  double HeightMm(double rho_mm) const;
  double SlopePerRho(double rho_mm) const;  // dh/drho
  // "field: problem" if the law cannot be used over [rho0, rho1], else empty (a table not
  // strictly increasing, a gain <= 0, k <= 1, rho1 beyond the table).
  std::string Check(double rho0_mm, double rho1_mm) const;
};

struct OdeDesignSpec {
  double focal_length_mm = 0.0;     // f
  double distance_mm = 0.0;         // d, the reference cylinder's radius
  double start_height_mm = 0.0;     // F0 = F(0), image plane to mirror vertex
  double rim_limit_mm = 0.0;        // t1, the largest mirror radius allowed
  double rho0_mm = 0.0, rho1_mm = 0.0;  // the imager's used radii
  ImagingLaw law;
  // "field: problem" for parameters that cannot make a mirror, else empty.
  std::string Check() const;
};

struct ProfileSample {
  double radius_mm;  // t
  double height_mm;  // F(t)
  double slope;      // dF/dt
};

struct OdeDesign {
  std::vector<ProfileSample> profile;  // t from 0 to the end of the field
  double t_start_mm = 0.0, t_end_mm = 0.0;  // the mirror radii imaged at rho0 and at the field's end
  double rho_end_mm = 0.0;                  // rho1, or the rim's image if that comes first
  bool ended_at_rim = false;                // the field ends at t1 (inside rho1)
  double phi0_deg = 0.0, phi1_deg = 0.0;    // elevation at rho0 and at the field's end
  long ode_steps = 0;
};

// Integrates Eq. 7 from the axis. Throws InputError "design: problem at t = x mm" when the
// mirror folds back (slope beyond 1e3), turns below the pinhole, or sends a ray that never
// reaches the cylinder, and when rho1 lies beyond the image of the rim (t1) by more than
// 5 % (the seed's own uniform design reaches 0.2378 of 0.24 cm at its rim; the paper
// clips the imager there, and so does this).
OdeDesign SolveMirrorOde(const OdeDesignSpec& spec, int samples = 3001);

// Eq. 6: the reflected ray's slope dz/drho at a mirror point (t, F, F') for a pinhole at f.
double ReflectedSlope(double t_mm, double height_mm, double slope, double focal_length_mm);
// Elevation (deg, from -z) of a ray leaving the axis side with slope C outward.
double ElevationDeg(double reflected_slope);

}  // namespace omnical
