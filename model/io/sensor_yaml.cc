// Sensor file reader and writer (yaml-cpp). Every field is checked; an unknown field is
// an error too, because a misspelt optional key would otherwise be silently ignored.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <set>
#include <sstream>

#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/io/profile_table.h"
#include "model/io/sensor_yaml.h"
#include "model/io/yaml_field_reader.h"

namespace omnical {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

using FieldReader = YamlFieldReader;

// A lens or profile's fields read into its flat parameter array (model/parameter_field.h).
std::vector<double> ReadFields(const FieldReader& reader, const YAML::Node& section, const std::string& where,
                               const ParameterField* fields, size_t num_fields) {
  std::vector<double> params;
  for (size_t f = 0; f < num_fields; ++f) {
    const ParameterField& field = fields[f];
    const std::string name = where + "." + field.key;
    const YAML::Node node = section[field.key];
    if (field.is_list()) {
      if (!node) {
        if (field.min_count > 0) reader.Fail(name, "missing");
        continue;
      }
      for (double value : reader.Numbers(node, name, field.min_count, field.max_count)) {
        if (!(std::abs(value) <= field.bound)) reader.Fail(name, "magnitudes must be <= " + FieldReader::Format(field.bound));
        params.push_back(value);
      }
    } else if (!node && field.optional) {
      params.push_back(0.0);
    } else if (field.domain == FieldDomain::kPositive) {
      params.push_back(reader.Positive(node, name, field.bound));
    } else {
      params.push_back(reader.Bounded(node, name, field.bound));
    }
  }
  return params;
}

// A domain problem "key: reason" of a section's field is reported at that field.
[[noreturn]] void FailDomain(const FieldReader& reader, const std::string& where, const std::string& why) {
  const size_t colon = why.find(": ");
  if (colon != std::string::npos && why.find(' ') == colon + 1) reader.Fail(where + "." + why.substr(0, colon), why.substr(colon + 2));
  reader.Fail(where, why);
}

template <typename Fields>
std::set<std::string> Keys(const Fields& fields, std::set<std::string> keys) {
  for (const ParameterField& field : fields) keys.insert(field.key);
  return keys;
}

struct SectionsRead {
  std::string lens, profile;
  int width = 0, height = 0;
  double body_radius_mm = 0.0, rim_mm = 0.0;
};

SectionsRead ReadCommon(const FieldReader& reader, const YAML::Node& root) {
  SectionsRead read;
  const YAML::Node camera = reader.Section(root, "camera");
  read.lens = reader.Text(camera["model"], "camera.model");
  const YAML::Node size = camera["image_size"];
  if (!size) reader.Fail("camera.image_size", "missing");
  const std::vector<double> wh = reader.Numbers(size, "camera.image_size", 2, 2);
  for (int k = 0; k < 2; ++k)
    if (!(wh[k] >= 1.0 && wh[k] <= 1e6 && wh[k] == std::floor(wh[k])))
      reader.Fail("camera.image_size", "must be two positive whole numbers [width, height]");
  read.width = static_cast<int>(wh[0]);
  read.height = static_cast<int>(wh[1]);
  read.body_radius_mm = camera["body_radius_mm"] ? reader.Bounded(camera["body_radius_mm"], "camera.body_radius_mm", 1e5) : 0.0;
  if (read.body_radius_mm < 0.0) reader.Fail("camera.body_radius_mm", "must be >= 0");
  const std::vector<std::string> lenses = LensNames();
  if (std::find(lenses.begin(), lenses.end(), read.lens) == lenses.end())
    reader.Fail("camera.model", "unknown lens model '" + read.lens + "' (expected " + JoinChoices(lenses) + ")");
  return read;
}

MirrorPose<double> ReadPose(const FieldReader& reader, const YAML::Node& root) {
  const YAML::Node pose = reader.Section(root, "pose");
  reader.RejectUnknown(pose, "pose", {"m", "tilt_deg", "decenter_mm"});
  MirrorPose<double> out{};
  out.m_mm = reader.Positive(pose["m"], "pose.m", 1e6);
  if (pose["tilt_deg"]) {
    const std::vector<double> tilt = reader.Numbers(pose["tilt_deg"], "pose.tilt_deg", 2, 2);
    for (double t : tilt)
      if (std::abs(t) >= 45.0) reader.Fail("pose.tilt_deg", "tilt must be within +-45 deg");
    out.tilt_x_rad = tilt[0] * kDegToRad;
    out.tilt_y_rad = tilt[1] * kDegToRad;
  }
  if (pose["decenter_mm"]) {
    const std::vector<double> decenter = reader.Numbers(pose["decenter_mm"], "pose.decenter_mm", 2, 2);
    for (double d : decenter)
      if (std::abs(d) > 1e5) reader.Fail("pose.decenter_mm", "magnitude must be <= 1e5 mm");
    out.decenter_x_mm = decenter[0];
    out.decenter_y_mm = decenter[1];
  }
  return out;
}

// The registered model of the file's lens and profile, every field read through the
// registry's descriptions (a tabulated profile reads its table). Sections in the order
// camera, pose, mirror: the first problem found is the one reported.
SensorModel ReadModel(const FieldReader& reader, const YAML::Node& root) {
  const SectionsRead read = ReadCommon(reader, root);
  const YAML::Node camera = root["camera"];
  std::vector<double> lens;
  bool lens_read = false;
  ForEachModelType([&](auto tag) {
    using Lens = typename decltype(tag)::type::LensType;
    if (lens_read || read.lens != Lens::kName) return;
    lens_read = true;
    reader.RejectUnknown(camera, "camera", Keys(Lens::kFields, {"model", "image_size", "body_radius_mm"}));
    lens = ReadFields(reader, camera, "camera", Lens::kFields.data(), Lens::kFields.size());
    if (const std::string why = Lens::FromParams(lens.data()).CheckDomain(); !why.empty()) FailDomain(reader, "camera", why);
  });
  const MirrorPose<double> pose = ReadPose(reader, root);
  const YAML::Node mirror = reader.Section(root, "mirror");
  const std::string profile = reader.Text(mirror["profile"], "mirror.profile");
  const std::vector<std::string> profiles = ProfileNames();
  if (std::find(profiles.begin(), profiles.end(), profile) == profiles.end())
    reader.Fail("mirror.profile", "unknown profile '" + profile + "' (expected " + JoinChoices(profiles) + ")");
  const double rim_mm = reader.Positive(mirror["rim_radius"], "mirror.rim_radius", kMaxRimRadiusMm);
  if (rim_mm < kMinRimRadiusMm) reader.Fail("mirror.rim_radius", "must be >= 1e-3 mm");
  std::optional<SensorModel> model;
  ForEachModelType([&](auto tag) {
    using Model = typename decltype(tag)::type;
    using Profile = typename Model::ProfileType;
    if (model || read.lens != Model::LensType::kName || profile != Profile::kName) return;
    Model m;
    m.lens = Model::LensType::FromParams(lens.data());
    m.pose = pose;
    m.rim_radius_mm = rim_mm;
    if constexpr (kFittedProfile<Profile>) {
      const auto& settings = ProfileSettings<Profile>::kFields;
      reader.RejectUnknown(mirror, "mirror", Keys(settings, Keys(Profile::kFields, {"profile", "rim_radius"})));
      const std::vector<double> setting_values = ReadFields(reader, mirror, "mirror", settings.data(), settings.size());
      const std::vector<double> shape = ReadFields(reader, mirror, "mirror", Profile::kFields.data(), Profile::kFields.size());
      m.mirror = Profile::FromParams(shape.data(), static_cast<int>(shape.size()));
      if constexpr (kHasSettings<Profile>) m.mirror.SetSettings(setting_values.data());
      // Reported at the field it names ("knots: ..."), as the lens's (ValidateSensorModel
      // would repeat the check with "mirror: " only).
      if (const std::string why = m.mirror.CheckDomain(rim_mm); !why.empty()) FailDomain(reader, "mirror", why);
    } else {
      reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "table"});
      std::filesystem::path table = reader.Text(mirror["table"], "mirror.table");
      if (table.is_relative()) table = std::filesystem::path(reader.path()).parent_path() / table;
      m.mirror.source = std::filesystem::weakly_canonical(table).string();
      try {
        m.mirror.spline = LoadProfileTable(table.string());
      } catch (const InputError& error) {
        reader.Fail("mirror.table", std::string("cannot read the profile table: ") + error.what());
      }
    }
    m.image_width_px = read.width;
    m.image_height_px = read.height;
    m.camera_body_radius_mm = read.body_radius_mm;
    model = m;
  });
  return *model;
}

// A lens or profile's fields written from its flat parameter array: a scalar as its key
// (left out where 0 and omitted_when_zero), a list as a flow sequence.
void WriteFields(YAML::Emitter& out, const ParameterField* fields, size_t num_fields, const std::vector<int>& counts,
                 const double* params) {
  int index = 0;
  for (size_t f = 0; f < num_fields; ++f) {
    if (!fields[f].is_list()) {
      const double value = params[index++];
      if (!(fields[f].omitted_when_zero && value == 0.0)) out << YAML::Key << fields[f].key << YAML::Value << value;
      continue;
    }
    if (counts[f] == 0) continue;
    out << YAML::Key << fields[f].key << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (int k = 0; k < counts[f]; ++k) out << params[index++];
    out << YAML::EndSeq;
  }
}

}  // namespace


namespace {

Sensor SensorFromRoot(const YAML::Node& root, const FieldReader& reader) {
  const std::string& path = reader.path();
  if (!root.IsMap()) reader.Fail("", "expected a map with camera, mirror and pose sections");
  try {
    // tolerances: the design tolerances of a guess, read by calib (design_tolerances.h).
    reader.RejectUnknown(root, "", {"camera", "mirror", "pose", "tolerances"});
    SensorModel model = ReadModel(reader, root);
    if (std::string why = ValidateSensorModel(model); !why.empty()) throw InputError(path + ": " + why);
    return Sensor(std::move(model));
  } catch (const YAML::Exception& error) {
    reader.Fail("", std::string("unexpected YAML structure: ") + error.what());
  }
}

}  // namespace

Sensor LoadSensorYaml(const std::string& path) {
  const FieldReader reader(path);
  return SensorFromRoot(reader.LoadFile(), reader);
}

Sensor ParseSensorYaml(const std::string& yaml_text, const std::string& source) {
  const FieldReader reader(source);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& error) {
    reader.Fail("", std::string("malformed YAML: ") + error.what());
  }
  return SensorFromRoot(root, reader);
}

std::string SensorYamlText(const Sensor& sensor) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  std::visit(
      [&](const auto& m) {
        using Model = std::decay_t<decltype(m)>;
        out << YAML::BeginMap;
        out << YAML::Key << "camera" << YAML::Value << YAML::Flow << YAML::BeginMap;
        out << YAML::Key << "model" << YAML::Value << Model::LensType::kName;
        out << YAML::Key << "image_size" << YAML::Value << YAML::Flow << YAML::BeginSeq << m.image_width_px
            << m.image_height_px << YAML::EndSeq;
        using Lens = typename Model::LensType;
        using Profile = typename Model::ProfileType;
        double lens[Lens::kNumParams];
        m.lens.ToParams(lens);
        WriteFields(out, Lens::kFields.data(), Lens::kFields.size(), std::vector<int>(Lens::kNumParams, 1), lens);
        if (m.camera_body_radius_mm > 0.0)
          out << YAML::Key << "body_radius_mm" << YAML::Value << m.camera_body_radius_mm;
        out << YAML::EndMap;

        out << YAML::Key << "mirror" << YAML::Value << YAML::Flow << YAML::BeginMap;
        out << YAML::Key << "profile" << YAML::Value << Profile::kName;
        out << YAML::Key << "rim_radius" << YAML::Value << m.rim_radius_mm;
        if constexpr (kHasSettings<Profile>) {
          constexpr size_t kCount = ProfileSettings<Profile>::kFields.size();
          double settings[kCount];
          m.mirror.ToSettings(settings);
          WriteFields(out, ProfileSettings<Profile>::kFields.data(), kCount, std::vector<int>(kCount, 1), settings);
        }
        if constexpr (kFittedProfile<Profile>) {
          std::vector<double> shape(m.mirror.NumParams());
          m.mirror.ToParams(shape.data());
          WriteFields(out, Profile::kFields.data(), Profile::kFields.size(), FieldCounts<Profile>(m.mirror.NumParams()),
                      shape.data());
        } else {
          out << YAML::Key << "table" << YAML::Value << m.mirror.source;
        }
        out << YAML::EndMap;

        out << YAML::Key << "pose" << YAML::Value << YAML::Flow << YAML::BeginMap;
        out << YAML::Key << "m" << YAML::Value << m.pose.m_mm;
        out << YAML::Key << "tilt_deg" << YAML::Value << YAML::Flow << YAML::BeginSeq
            << m.pose.tilt_x_rad / kDegToRad << m.pose.tilt_y_rad / kDegToRad << YAML::EndSeq;
        out << YAML::Key << "decenter_mm" << YAML::Value << YAML::Flow << YAML::BeginSeq << m.pose.decenter_x_mm
            << m.pose.decenter_y_mm << YAML::EndSeq;
        out << YAML::EndMap;
        out << YAML::EndMap;
      },
      sensor.model());
  return std::string(out.c_str()) + "\n";
}

void SaveSensorYaml(const Sensor& sensor, const std::string& path) {
  const std::string text = SensorYamlText(sensor);
  WriteFileAtomically(path, [&](std::ostream& stream) { stream << text; });
}

}  // namespace omnical
