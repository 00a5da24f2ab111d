// Sensor file reader and writer (yaml-cpp). Every field is checked; an unknown field is
// an error too, because a misspelt optional key would otherwise be silently ignored.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
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

struct LensChoice {
  PinholeLens<double> pinhole{};
  OrthographicLens<double> orthographic{};
  bool is_orthographic = false;
  int width = 0, height = 0;
  double body_radius_mm = 0.0;
};

LensChoice ReadCamera(const FieldReader& reader, const YAML::Node& root) {
  const YAML::Node camera = reader.Section(root, "camera");
  LensChoice lens;
  const std::string model = reader.Text(camera["model"], "camera.model");
  const YAML::Node size = camera["image_size"];
  if (!size) reader.Fail("camera.image_size", "missing");
  const std::vector<double> wh = reader.Numbers(size, "camera.image_size", 2, 2);
  for (int k = 0; k < 2; ++k)
    if (!(wh[k] >= 1.0 && wh[k] <= 1e6 && wh[k] == std::floor(wh[k])))
      reader.Fail("camera.image_size", "must be two positive whole numbers [width, height]");
  lens.width = static_cast<int>(wh[0]);
  lens.height = static_cast<int>(wh[1]);
  lens.body_radius_mm = camera["body_radius_mm"] ? reader.Bounded(camera["body_radius_mm"], "camera.body_radius_mm", 1e5) : 0.0;
  if (lens.body_radius_mm < 0.0) reader.Fail("camera.body_radius_mm", "must be >= 0");
  if (model == "pinhole") {
    reader.RejectUnknown(camera, "camera", {"model", "image_size", "fx", "fy", "cx", "cy", "k1", "k2", "body_radius_mm"});
    PinholeLens<double>& p = lens.pinhole;
    p.fx_px = reader.Positive(camera["fx"], "camera.fx", 1e8);
    p.fy_px = reader.Positive(camera["fy"], "camera.fy", 1e8);
    if (p.fx_px < 1e-3 || p.fy_px < 1e-3) reader.Fail("camera.fx", "focal lengths below 1e-3 px are not a camera");
    p.cx_px = reader.Bounded(camera["cx"], "camera.cx", 1e7);
    p.cy_px = reader.Bounded(camera["cy"], "camera.cy", 1e7);
    p.k1 = camera["k1"] ? reader.Bounded(camera["k1"], "camera.k1", 1e6) : 0.0;
    p.k2 = camera["k2"] ? reader.Bounded(camera["k2"], "camera.k2", 1e6) : 0.0;
  } else if (model == "orthographic") {
    reader.RejectUnknown(camera, "camera", {"model", "image_size", "scale_px_per_mm", "cx", "cy", "body_radius_mm"});
    lens.is_orthographic = true;
    lens.orthographic.scale_px_per_mm = reader.Positive(camera["scale_px_per_mm"], "camera.scale_px_per_mm", 1e6);
    lens.orthographic.cx_px = reader.Bounded(camera["cx"], "camera.cx", 1e7);
    lens.orthographic.cy_px = reader.Bounded(camera["cy"], "camera.cy", 1e7);
  } else {
    reader.Fail("camera.model", "unknown lens model '" + model + "' (expected pinhole or orthographic)");
  }
  return lens;
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

template <template <typename> class Profile>
SensorModel Assemble(const Profile<double>& profile, const LensChoice& lens, const MirrorPose<double>& pose,
                     double rim_mm) {
  auto fill = [&](auto model) -> SensorModel {
    model.mirror = profile;
    model.pose = pose;
    model.rim_radius_mm = rim_mm;
    model.image_width_px = lens.width;
    model.image_height_px = lens.height;
    model.camera_body_radius_mm = lens.body_radius_mm;
    return model;
  };
  if (lens.is_orthographic) {
    Catadioptric<double, Profile, OrthographicLens> model;
    model.lens = lens.orthographic;
    return fill(model);
  }
  Catadioptric<double, Profile, PinholeLens> model;
  model.lens = lens.pinhole;
  return fill(model);
}

SensorModel ReadMirror(const FieldReader& reader, const YAML::Node& root, const LensChoice& lens,
                       const MirrorPose<double>& pose) {
  const YAML::Node mirror = reader.Section(root, "mirror");
  const std::string profile = reader.Text(mirror["profile"], "mirror.profile");
  const double rim = reader.Positive(mirror["rim_radius"], "mirror.rim_radius", 1e5);
  if (rim < 1e-3) reader.Fail("mirror.rim_radius", "must be >= 1e-3 mm");
  if (profile == "sphere") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "A"});
    return Assemble(SphereProfile<double>{reader.Positive(mirror["A"], "mirror.A", 1e7)}, lens, pose, rim);
  }
  if (profile == "polynomial") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "coefficients"});
    if (!mirror["coefficients"]) reader.Fail("mirror.coefficients", "missing");
    const std::vector<double> c = reader.Numbers(mirror["coefficients"], "mirror.coefficients", 1,
                                                 EvenPolynomialProfile<double>::kMaxCoefficients);
    return Assemble(EvenPolynomialProfile<double>::FromParams(c.data(), static_cast<int>(c.size())), lens, pose, rim);
  }
  if (profile == "hyperboloid") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "A", "B"});
    return Assemble(HyperboloidProfile<double>{reader.Positive(mirror["A"], "mirror.A", 1e7),
                                               reader.Positive(mirror["B"], "mirror.B", 1e7)},
                    lens, pose, rim);
  }
  if (profile == "paraboloid") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "A"});
    return Assemble(ParaboloidProfile<double>{reader.Positive(mirror["A"], "mirror.A", 1e7)}, lens, pose, rim);
  }
  if (profile == "tabulated") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "table"});
    std::filesystem::path table = reader.Text(mirror["table"], "mirror.table");
    if (table.is_relative()) table = std::filesystem::path(reader.path()).parent_path() / table;
    TabulatedProfile<double> tabulated;
    tabulated.source = std::filesystem::weakly_canonical(table).string();
    try {
      tabulated.spline = LoadProfileTable(table.string());
    } catch (const InputError& error) {
      reader.Fail("mirror.table", std::string("cannot read the profile table: ") + error.what());
    }
    return Assemble(tabulated, lens, pose, rim);
  }
  reader.Fail("mirror.profile", "unknown profile '" + profile +
                                    "' (expected sphere, polynomial, hyperboloid, paraboloid or tabulated)");
}

}  // namespace


namespace {

Sensor SensorFromRoot(const YAML::Node& root, const FieldReader& reader) {
  const std::string& path = reader.path();
  if (!root.IsMap()) reader.Fail("", "expected a map with camera, mirror and pose sections");
  try {
    // tolerances: the design tolerances of a guess, read by calib (design_tolerances.h).
    reader.RejectUnknown(root, "", {"camera", "mirror", "pose", "tolerances"});
    const LensChoice lens = ReadCamera(reader, root);
    const MirrorPose<double> pose = ReadPose(reader, root);
    SensorModel model = ReadMirror(reader, root, lens, pose);
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
        if constexpr (Model::kOrthographic) {
          out << YAML::Key << "scale_px_per_mm" << YAML::Value << m.lens.scale_px_per_mm;
        } else {
          out << YAML::Key << "fx" << YAML::Value << m.lens.fx_px << YAML::Key << "fy" << YAML::Value << m.lens.fy_px;
        }
        out << YAML::Key << "cx" << YAML::Value << m.lens.cx_px << YAML::Key << "cy" << YAML::Value << m.lens.cy_px;
        if constexpr (!Model::kOrthographic) {
          out << YAML::Key << "k1" << YAML::Value << m.lens.k1 << YAML::Key << "k2" << YAML::Value << m.lens.k2;
        }
        if (m.camera_body_radius_mm > 0.0)
          out << YAML::Key << "body_radius_mm" << YAML::Value << m.camera_body_radius_mm;
        out << YAML::EndMap;

        out << YAML::Key << "mirror" << YAML::Value << YAML::Flow << YAML::BeginMap;
        out << YAML::Key << "profile" << YAML::Value << Model::ProfileType::kName;
        out << YAML::Key << "rim_radius" << YAML::Value << m.rim_radius_mm;
        using Profile = typename Model::ProfileType;
        if constexpr (std::is_same_v<Profile, SphereProfile<double>>) {
          out << YAML::Key << "A" << YAML::Value << m.mirror.radius_of_curvature_mm;
        } else if constexpr (std::is_same_v<Profile, EvenPolynomialProfile<double>>) {
          out << YAML::Key << "coefficients" << YAML::Value << YAML::Flow << YAML::BeginSeq;
          for (int k = 0; k < m.mirror.num_coefficients; ++k) out << m.mirror.coefficients[k];
          out << YAML::EndSeq;
        } else if constexpr (std::is_same_v<Profile, HyperboloidProfile<double>>) {
          out << YAML::Key << "A" << YAML::Value << m.mirror.a_mm << YAML::Key << "B" << YAML::Value << m.mirror.b_mm;
        } else if constexpr (std::is_same_v<Profile, ParaboloidProfile<double>>) {
          out << YAML::Key << "A" << YAML::Value << m.mirror.focal_distance_mm;
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
