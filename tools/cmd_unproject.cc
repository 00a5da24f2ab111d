// omnical unproject: pixels -> world rays (origin on the mirror, unit direction).
#include <iomanip>
#include <ostream>

#include "model/io/csv_reader.h"
#include "model/sensor.h"
#include "tools/commands.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {

Command UnprojectCommand() {
  return {"unproject", "Unproject pixels to rays: rows u,v -> ox,oy,oz,dx,dy,dz,status (camera frame, mm)",
          [](CLI::App& sub, const Context&) -> CommandAction {
            auto sensor_path = std::make_shared<std::string>();
            auto pixels_path = std::make_shared<std::string>();
            auto out_path = std::make_shared<std::string>();
            sub.add_option("--sensor", *sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--pixels", *pixels_path, "CSV with rows u,v in pixels")->required();
            sub.add_option("--out", *out_path, "Output CSV (default: standard output)");
            return [=]() {
              const Sensor sensor = LoadSensorYaml(*sensor_path);
              const CsvTable table = ReadNumericCsv(*pixels_path, 2);
              Eigen::Matrix2Xd pixels(2, table.rows.size());
              for (size_t i = 0; i < table.rows.size(); ++i) pixels.col(i) << table.rows[i][0], table.rows[i][1];
              Eigen::Matrix3Xd origins, directions;
              std::vector<ProjectionStatus> statuses;
              sensor.UnprojectBatch(pixels, &origins, &directions, &statuses);
              WriteOutput(*out_path, [&](std::ostream& out) {
                out << "ox,oy,oz,dx,dy,dz,status\n" << std::setprecision(15);
                for (size_t i = 0; i < statuses.size(); ++i) {
                  if (statuses[i] == ProjectionStatus::kOk) {
                    out << origins(0, i) << ',' << origins(1, i) << ',' << origins(2, i) << ',' << directions(0, i)
                        << ',' << directions(1, i) << ',' << directions(2, i);
                  } else {
                    out << "nan,nan,nan,nan,nan,nan";
                  }
                  out << ',' << StatusName(statuses[i]) << '\n';
                }
              });
            };
          }};
}

}  // namespace omnical::cli
