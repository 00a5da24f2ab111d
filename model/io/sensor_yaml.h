// sensor.yaml: a Sensor written and read (docs/file-formats.md "Sensor file"), tables of
// tabulated mirrors included (model/io/profile_table.h).
#pragma once

#include <string>

#include "model/sensor.h"

namespace omnical {

// Sensor file (YAML, docs/file-formats.md "Sensor file"). Throws InputError "file: field: problem".
Sensor LoadSensorYaml(const std::string& path);
// The same from YAML text (a sensor inline in another file); `source` names it in
// messages and relative table paths resolve against its directory.
Sensor ParseSensorYaml(const std::string& yaml_text, const std::string& source);
// Writes the same format (atomically). Throws InputError if the file cannot be written.
void SaveSensorYaml(const Sensor& sensor, const std::string& path);
// The text SaveSensorYaml writes.
std::string SensorYamlText(const Sensor& sensor);
}  // namespace omnical
