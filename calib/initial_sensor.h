// Starting sensors for the fit when the owner has less than a full guess.
//
// From the rim circle alone (no datasheet, no guess): an orthographic lens with the
// principal point at the rim's centre and the scale gauge fixed so the mirror's rim is
// kNominalRimRadiusMm (only scale x mirror size is observable through such a lens; the fit
// holds the scale), and a mirror of the requested family curved so the rim's ray leaves at
// `rim_field_deg` from the mirror's -z axis (Omega). A reflected ray turns by twice the
// surface's slope angle, so that is a slope at the rim: atan of it is Omega / 2.
// Or through a pinhole (lens "pinhole": a perspective camera in front of an unknown
// mirror): on the mirror's axis, the principal point at the rim's centre, no distortion,
// seeing the rim kNominalRimViewDeg (Theta) off its axis, which sets m and the focal
// length; the rim ray then leaves at Omega = Theta + twice the slope angle. The lens's
// distance m and focal length trade off like a dolly zoom when the mirror's shape is free,
// so the fit holds m there (calibrate.h, CalibrationOptions::lens).
//
// From a guess with another profile family: the guess's mirror re-expressed in the
// requested family by least squares on its sag and slope over the rim (Ceres), the lens,
// pose and rim kept.
#pragma once

#include <Eigen/Core>
#include <string>

#include "calib/rim_circle.h"
#include "model/sensor.h"

namespace omnical {

constexpr double kNominalRimRadiusMm = 20.0;
constexpr double kDefaultRimFieldDeg = 105.0;
constexpr int kDefaultPolynomialCoefficients = 3;
// The seed papers' designs see the rim 12 deg off the lens axis.
constexpr double kNominalRimViewDeg = 12.0;

// profile: sphere, paraboloid or polynomial (hyperboloid needs a pinhole at its focus,
// hence a guess). Throws InputError naming the field `profile` otherwise; lens:
// orthographic or pinhole (InputError naming `lens` otherwise).
Sensor SensorFromRimCircle(const RimCircle& rim, int image_width_px, int image_height_px, const std::string& profile,
                           double rim_field_deg = kDefaultRimFieldDeg, const std::string& lens = "orthographic");

// profile: any the fit can shape (ProfileNames(false)); the guess itself if it already
// has that profile. Throws InputError if the result is not a valid sensor.
// knots > 0: a spline with that many knots (model/spline_profile.h; converted again if
// the guess is a spline with another count); InputError naming `knots` for another profile.
Sensor ConvertProfile(const Sensor& guess, const std::string& profile, int knots = 0);

}  // namespace omnical
