// The profile table file of a tabulated mirror (CSV, mm; docs/file-formats.md "Profile tables"): rows
// "x_mm, z_mm[, dz_dx]" from the vertex (x = 0, z = 0) to the rim, after an optional
// header and '#' comment lines. Read and written here, so the format lives in one place.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model/tabulated_profile.h"

namespace omnical {

// A profile as the table holds it: radius x from the vertex, sag z from the vertex (away
// from the lens), slope dz/dx; x strictly increasing from 0.
struct ProfileTable {
  std::vector<double> radius_mm, sag_mm, slope;
};

// Loads "r,z[,dz/dr,...]" rows (mm); a dz/dr column on every row clamps the end slope, and
// a non-zero one on the vertex row makes the vertex a cone point.
// Throws InputError naming the file, the line and the problem.
std::shared_ptr<const ProfileSpline> LoadProfileTable(const std::string& path);

// Writes the table with all three columns (15 significant digits) atomically; `source`
// names what made it in the comment line ("design ode"). Throws InputError naming the
// path when the file cannot be written.
void WriteProfileTable(const ProfileTable& table, const std::string& source, const std::string& path);

}  // namespace omnical
