// A dimensioned drawing of a mirror profile a workshop can machine from: the section
// through the axis to scale, the centre line, the diameter and the rim sag dimensioned,
// and a table of ordinates (radius, sag, slope) at even stations. Written as SVG (vector,
// for the drawing office) and PNG from one layout, so the two always agree.
#pragma once

#include <string>
#include <vector>

namespace omnical {

struct ProfileDrawing {
  std::string title;               // e.g. "omnical design fit: polynomial, equidistant"
  std::vector<double> radius_mm;   // strictly increasing from 0 (the vertex) to the rim
  std::vector<double> sag_mm;      // z from the vertex, away from the lens
  std::vector<double> slope;       // dz/dr
  std::vector<std::string> notes;  // lines printed under the table (lens distance, source)
  int stations = 16;               // ordinate rows, evenly spaced in radius, rim included
};

// The profile table a tabulated mirror reads (x_mm, z_mm, dz_dx; see README "Sensor
// file"), from the drawing's samples; `source` names the subcommand in its comment line.
void WriteProfileTable(const ProfileDrawing& drawing, const std::string& source, const std::string& path);

// Throws InputError naming the path when a file cannot be written.
void WriteProfileDrawing(const ProfileDrawing& drawing, const std::string& svg_path, const std::string& png_path);

}  // namespace omnical
