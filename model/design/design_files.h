// The files the design and optics jobs write besides the profile table
// (model/io/profile_table.h) and the figures (calib/report): JSON summaries and CSV curves.
// Each writes atomically and throws InputError naming the path when it cannot.
#pragma once

#include <string>

#include "model/design/characterize.h"
#include "model/design/design_fit_job.h"
#include "model/design/design_ode_job.h"

namespace omnical {

// design ode: design.json (field of view, law check, ODE, sensor, distance sensitivity);
// law_ratio.csv (rho_mm and the ratio at each checked distance); sensor.yaml (the
// tabulated sensor naming options.table_file, with the pixel pitch in a comment).
void WriteOdeDesignJson(const DesignOdeResult& result, const std::string& path);
void WriteLawRatioCsv(const DesignOdeResult& result, const std::string& path);
void WriteOdeDesignSensorYaml(const DesignOdeResult& result, const std::string& table_file, const std::string& path);

// design fit: design.json (targets, parameters normalised and in mm, the achieved and
// compared laws, the solver); characteristic.csv (x, Omega, h, the law's h, z_v).
// sensor_file is the name design.json gives the sensor.
void WriteFitDesignJson(const DesignFitResult& result, const std::string& sensor_file, const std::string& path);
void WriteFitCharacteristicCsv(const DesignFitResult& result, const std::string& path);

// characterize: characteristics.csv (every quantity per field sample) and summary.json;
// sensor_file is the name summary.json gives the analysed sensor.
void WriteCharacteristicsCsv(const CharacterizeResult& result, const std::string& path);
void WriteCharacterizeSummaryJson(const CharacterizeResult& result, const std::string& sensor_file,
                                  const std::string& path);

}  // namespace omnical
