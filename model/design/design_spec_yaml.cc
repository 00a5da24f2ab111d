#include "model/design/design_spec_yaml.h"

#include "model/io/csv_reader.h"
#include "model/input_error.h"
#include "model/io/yaml_field_reader.h"

namespace omnical {

void LoadLawTable(const std::string& path, ImagingLaw* law) {
  const CsvTable table = ReadNumericCsv(path, 2);
  law->kind = ImagingLaw::Kind::kTable;
  law->table_source = path;
  law->table_rho_mm.clear();
  law->table_h_mm.clear();
  for (const auto& row : table.rows) {
    law->table_rho_mm.push_back(row[0]);
    law->table_h_mm.push_back(row[1]);
  }
}

OdeDesignSpec LoadOdeDesignSpec(const std::string& path) {
  const YamlFieldReader reader(path);
  const YAML::Node root = reader.LoadFile();
  reader.RejectUnknown(root, "", {"focal_length_mm", "distance_mm", "start_height_mm", "rim_limit_mm", "imager", "law"});
  OdeDesignSpec spec;
  spec.focal_length_mm = reader.Positive(root["focal_length_mm"], "focal_length_mm", 1e6);
  spec.distance_mm = reader.Positive(root["distance_mm"], "distance_mm", 1e9);
  spec.start_height_mm = reader.Positive(root["start_height_mm"], "start_height_mm", 1e7);
  spec.rim_limit_mm = reader.Positive(root["rim_limit_mm"], "rim_limit_mm", 1e7);
  const YAML::Node imager = reader.Section(root, "imager");
  reader.RejectUnknown(imager, "imager", {"rho0_mm", "rho1_mm"});
  spec.rho0_mm = reader.NumberOr(imager, "rho0_mm", "imager", 0.0);
  spec.rho1_mm = reader.Positive(imager["rho1_mm"], "imager.rho1_mm", 1e6);
  const YAML::Node law = reader.Section(root, "law");
  const std::string type = reader.Text(law["type"], "law.type");
  if (type == "linear") {
    reader.RejectUnknown(law, "law", {"type", "gain", "offset_mm"});
    spec.law.kind = ImagingLaw::Kind::kLinear;
    spec.law.gain = reader.Number(law["gain"], "law.gain");
    spec.law.offset_mm = reader.Number(law["offset_mm"], "law.offset_mm");
  } else if (type == "logpolar") {
    reader.RejectUnknown(law, "law", {"type", "gain_mm", "offset_mm", "growth_rate"});
    spec.law.kind = ImagingLaw::Kind::kLogPolar;
    spec.law.gain = reader.Number(law["gain_mm"], "law.gain_mm");
    spec.law.offset_mm = reader.Number(law["offset_mm"], "law.offset_mm");
    spec.law.growth_rate = reader.Number(law["growth_rate"], "law.growth_rate");
    spec.law.rho0_mm = spec.rho0_mm;
  } else if (type == "table") {
    reader.RejectUnknown(law, "law", {"type", "file"});
    LoadLawTable(reader.Resolve(reader.Text(law["file"], "law.file")), &spec.law);
  } else {
    reader.Fail("law.type", "unknown law '" + type + "' (expected linear, logpolar or table)");
  }
  if (const std::string why = spec.Check(); !why.empty()) throw InputError(path + ": " + why);
  return spec;
}

}  // namespace omnical
