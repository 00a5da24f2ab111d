// Design tolerances of a sensor guess: how far each parameter of the built sensor may be
// from its design value (one standard deviation), as the bundle fit's weak priors
// (FitOptions::tolerances). Written in the guess's sensor file,
//   tolerances: { m_mm: 2, decenter_mm: 1, tilt_deg: 1, principal_point_px: 10, k1: 0.05 }
// or on the command line as "m_mm=2,tilt_deg=1". Names as FitResult names the
// parameters, or one of the pairs tilt_deg, decenter_mm, principal_point_px, focal_px.
#pragma once

#include <map>
#include <string>

#include "model/sensor.h"

namespace omnical {

using DesignTolerances = std::map<std::string, double>;

// The `tolerances` section of a sensor file (empty if it has none), checked against the
// sensor the same file describes. Throws InputError "file: tolerances.x: problem".
DesignTolerances ReadDesignTolerances(const std::string& sensor_path, const Sensor& sensor);

// "name=value,name=value"; throws InputError naming `field` (e.g. the CLI flag).
DesignTolerances ParseDesignTolerances(const std::string& text, const std::string& field);

}  // namespace omnical
