// omnical project: 3-D points (camera frame, mm) -> pixels through the exact model.
#include <iomanip>
#include <ostream>

#include "model/io/csv_reader.h"
#include "model/sensor.h"
#include "tools/commands.h"
#include "model/io/sensor_yaml.h"

namespace omnical::cli {

Command ProjectCommand() {
  return {"project", "Project 3-D points (camera frame, mm) to pixels: rows X,Y,Z -> u,v,status",
          [](CLI::App& sub, const Context&) -> CommandAction {
            auto sensor_path = std::make_shared<std::string>();
            auto points_path = std::make_shared<std::string>();
            auto out_path = std::make_shared<std::string>();
            sub.add_option("--sensor", *sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--points", *points_path, "CSV with rows X,Y,Z in mm, camera frame")->required();
            sub.add_option("--out", *out_path, "Output CSV (default: standard output)");
            return [=]() {
              const Sensor sensor = LoadSensorYaml(*sensor_path);
              const CsvTable table = ReadNumericCsv(*points_path, 3);
              Eigen::Matrix3Xd points(3, table.rows.size());
              for (size_t i = 0; i < table.rows.size(); ++i)
                points.col(i) << table.rows[i][0], table.rows[i][1], table.rows[i][2];
              Eigen::Matrix2Xd pixels;
              std::vector<ProjectionStatus> statuses;
              sensor.ProjectBatch(points, &pixels, &statuses);
              WriteOutput(*out_path, [&](std::ostream& out) {
                out << "u,v,status\n" << std::setprecision(15);
                for (size_t i = 0; i < statuses.size(); ++i) {
                  if (statuses[i] == ProjectionStatus::kOk) {
                    out << pixels(0, i) << ',' << pixels(1, i);
                  } else {
                    out << "nan,nan";
                  }
                  out << ',' << StatusName(statuses[i]) << '\n';
                }
              });
            };
          }};
}

}  // namespace omnical::cli
