// The spec file of `omnical design ode` (YAML, mm): the camera, the reference cylinder,
// the mirror's start and limit, the imager's used radii and the imaging law. See
// datasets-synthetic/designs/ for the seed's two designs.
//   focal_length_mm: 12.5
//   distance_mm: 2000        # d
//   start_height_mm: 155     # F0
//   rim_limit_mm: 30         # t1
//   imager: { rho0_mm: 0, rho1_mm: 2.4 }
//   law: { type: linear, gain: 2000, offset_mm: -4000 }
//     or { type: logpolar, gain_mm: 40, offset_mm: -4000, growth_rate: 1.02337 }
//     or { type: table, file: law.csv }   # rows rho_mm, h_mm (relative to the spec)
#pragma once

#include <string>

#include "model/design/mirror_design_ode.h"

namespace omnical {

// Throws InputError "file: field: problem".
OdeDesignSpec LoadOdeDesignSpec(const std::string& path);
// A law table file (rows rho_mm, h_mm) into `law` (kind kTable).
void LoadLawTable(const std::string& path, ImagingLaw* law);

}  // namespace omnical
