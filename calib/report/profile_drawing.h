// A dimensioned drawing of a mirror profile a workshop can machine from: the section
// through the axis to scale, the centre line, the diameter and the rim sag dimensioned,
// and a table of ordinates (radius, sag, slope) at even stations. Written as SVG (vector,
// for the drawing office) and PNG from one layout, so the two always agree.
#pragma once

#include <string>
#include <vector>

#include "model/io/profile_table.h"

namespace omnical {

struct ProfileDrawing {
  std::string title;               // e.g. "omnical design fit: polynomial, equidistant"
  ProfileTable profile;            // from the vertex to the rim (model/io/profile_table.h)
  std::vector<std::string> notes;  // lines printed under the table (lens distance, source)
  int stations = 16;               // ordinate rows, evenly spaced in radius, rim included
};

// Throws InputError naming the path when a file cannot be written.
void WriteProfileDrawing(const ProfileDrawing& drawing, const std::string& svg_path, const std::string& png_path);

}  // namespace omnical
