#include "model/io/profile_table.h"

#include <cmath>
#include <iomanip>
#include <ostream>
#include <stdexcept>

#include "model/io/atomic_write.h"
#include "model/io/csv_reader.h"
#include "model/input_error.h"

namespace omnical {

std::shared_ptr<const ProfileSpline> LoadProfileTable(const std::string& path) {
  const CsvTable table = ReadNumericCsv(path, 2);
  std::vector<double> radius, sag;
  bool slopes = true;
  for (const auto& row : table.rows) {
    radius.push_back(row[0]);
    sag.push_back(row[1]);
    slopes = slopes && row.size() >= 3;
  }
  try {
    const double end_slope = slopes ? table.rows.back()[2] : NAN;
    const double vertex_slope = slopes ? table.rows.front()[2] : 0.0;
    return std::make_shared<const ProfileSpline>(std::move(radius), std::move(sag), end_slope, vertex_slope);
  } catch (const std::invalid_argument& error) {
    throw InputError(InputMessage(path, "", error.what()));
  }
}

void WriteProfileTable(const ProfileTable& table, const std::string& source, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# mirror profile from omnical " << source << ": radius x, sag z from the vertex, slope dz/dx (mm)\n"
        << "x_mm,z_mm,dz_dx\n"
        << std::setprecision(15);
    for (size_t i = 0; i < table.radius_mm.size(); ++i)
      out << table.radius_mm[i] << ',' << table.sag_mm[i] << ',' << table.slope[i] << '\n';
  });
}

}  // namespace omnical
