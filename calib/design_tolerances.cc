#include "calib/design_tolerances.h"

#include <cmath>
#include <sstream>

#include "calib/bundle_fit.h"
#include "model/input_error.h"
#include "model/io/yaml_field_reader.h"

namespace omnical {

DesignTolerances ReadDesignTolerances(const std::string& sensor_path, const Sensor& sensor) {
  const YamlFieldReader reader(sensor_path);
  const YAML::Node root = reader.LoadFile();
  DesignTolerances tolerances;
  const YAML::Node section = root.IsMap() ? root["tolerances"] : YAML::Node();
  if (!section) return tolerances;
  if (!section.IsMap()) reader.Fail("tolerances", "must be a map of parameter names to tolerances");
  for (const auto& entry : section) {
    const std::string name = entry.first.as<std::string>();
    tolerances[name] = reader.Number(entry.second, "tolerances." + name);
  }
  FitOptions options;
  options.tolerances = tolerances;
  if (const std::string why = options.CheckFor(sensor); !why.empty()) throw InputError(sensor_path + ": " + why);
  return tolerances;
}

DesignTolerances ParseDesignTolerances(const std::string& text, const std::string& field) {
  DesignTolerances tolerances;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (item.empty()) continue;
    const size_t equals = item.find('=');
    double value = NAN;
    size_t used = 0;
    try {
      if (equals != std::string::npos) value = std::stod(item.substr(equals + 1), &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (equals == std::string::npos || equals == 0 || used == 0 || used != item.size() - equals - 1)
      throw InputError(field + ": '" + item + "' is not name=value (e.g. m_mm=2,tilt_deg=1)");
    tolerances[item.substr(0, equals)] = value;
  }
  return tolerances;
}

}  // namespace omnical
