// Sensor file reader and writer (yaml-cpp). Every field is checked; an unknown field is
// an error too, because a misspelt optional key would otherwise be silently ignored.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <set>
#include <sstream>

#include "model/atomic_write.h"
#include "model/input_error.h"
#include "model/sensor.h"

namespace omnical {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

class FieldReader {
 public:
  explicit FieldReader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw InputError(InputMessage(path_, field, problem));
  }

  YAML::Node Section(const YAML::Node& root, const std::string& name) const {
    const YAML::Node node = root[name];
    if (!node) Fail(name, "missing section");
    if (!node.IsMap()) Fail(name, "must be a map of fields");
    return node;
  }

  void RejectUnknown(const YAML::Node& map, const std::string& section, const std::set<std::string>& known) const {
    for (const auto& entry : map) {
      const std::string key = entry.first.as<std::string>();
      if (!known.count(key)) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        Fail(section + "." + key, "unknown field (expected one of: " + list + ")");
      }
    }
  }

  double Number(const YAML::Node& node, const std::string& field) const {
    if (!node) Fail(field, "missing");
    if (!node.IsScalar()) Fail(field, "must be a number");
    double value = 0.0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      Fail(field, "'" + node.Scalar() + "' is not a number");
    }
    if (!std::isfinite(value)) Fail(field, "must be finite");
    return value;
  }
  double Number(const YAML::Node& map, const std::string& key, const std::string& section) const {
    return Number(map[key], section + "." + key);
  }
  double NumberOr(const YAML::Node& map, const std::string& key, const std::string& section, double fallback) const {
    return map[key] ? Number(map[key], section + "." + key) : fallback;
  }
  double Positive(const YAML::Node& map, const std::string& key, const std::string& section) const {
    const double value = Number(map, key, section);
    if (!(value > 0.0)) Fail(section + "." + key, "must be > 0 (got " + Format(value) + ")");
    return value;
  }
  std::vector<double> Numbers(const YAML::Node& node, const std::string& field, size_t min_count,
                              size_t max_count) const {
    if (!node.IsSequence()) Fail(field, "must be a list of numbers");
    if (node.size() < min_count || node.size() > max_count) {
      Fail(field, min_count == max_count ? "must list " + std::to_string(min_count) + " numbers"
                                         : "must list " + std::to_string(min_count) + " to " +
                                               std::to_string(max_count) + " numbers");
    }
    std::vector<double> values;
    for (size_t i = 0; i < node.size(); ++i) values.push_back(Number(node[i], field + "[" + std::to_string(i) + "]"));
    return values;
  }
  std::string Text(const YAML::Node& map, const std::string& key, const std::string& section) const {
    const YAML::Node node = map[key];
    if (!node) Fail(section + "." + key, "missing");
    if (!node.IsScalar()) Fail(section + "." + key, "must be a string");
    return node.Scalar();
  }
  static std::string Format(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

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
  const std::string model = reader.Text(camera, "model", "camera");
  const YAML::Node size = camera["image_size"];
  if (!size) reader.Fail("camera.image_size", "missing");
  const std::vector<double> wh = reader.Numbers(size, "camera.image_size", 2, 2);
  for (int k = 0; k < 2; ++k)
    if (!(wh[k] >= 1.0 && wh[k] <= 1e6 && wh[k] == std::floor(wh[k])))
      reader.Fail("camera.image_size", "must be two positive whole numbers [width, height]");
  lens.width = static_cast<int>(wh[0]);
  lens.height = static_cast<int>(wh[1]);
  lens.body_radius_mm = reader.NumberOr(camera, "body_radius_mm", "camera", 0.0);
  if (lens.body_radius_mm < 0.0) reader.Fail("camera.body_radius_mm", "must be >= 0");
  if (model == "pinhole") {
    reader.RejectUnknown(camera, "camera", {"model", "image_size", "fx", "fy", "cx", "cy", "k1", "k2", "body_radius_mm"});
    PinholeLens<double>& p = lens.pinhole;
    p.fx_px = reader.Positive(camera, "fx", "camera");
    p.fy_px = reader.Positive(camera, "fy", "camera");
    p.cx_px = reader.Number(camera, "cx", "camera");
    p.cy_px = reader.Number(camera, "cy", "camera");
    p.k1 = reader.NumberOr(camera, "k1", "camera", 0.0);
    p.k2 = reader.NumberOr(camera, "k2", "camera", 0.0);
  } else if (model == "orthographic") {
    reader.RejectUnknown(camera, "camera", {"model", "image_size", "scale_px_per_mm", "cx", "cy", "body_radius_mm"});
    lens.is_orthographic = true;
    lens.orthographic.scale_px_per_mm = reader.Positive(camera, "scale_px_per_mm", "camera");
    lens.orthographic.cx_px = reader.Number(camera, "cx", "camera");
    lens.orthographic.cy_px = reader.Number(camera, "cy", "camera");
  } else {
    reader.Fail("camera.model", "unknown lens model '" + model + "' (expected pinhole or orthographic)");
  }
  return lens;
}

MirrorPose<double> ReadPose(const FieldReader& reader, const YAML::Node& root) {
  const YAML::Node pose = reader.Section(root, "pose");
  reader.RejectUnknown(pose, "pose", {"m", "tilt_deg", "decenter_mm"});
  MirrorPose<double> out{};
  out.m_mm = reader.Positive(pose, "m", "pose");
  if (pose["tilt_deg"]) {
    const std::vector<double> tilt = reader.Numbers(pose["tilt_deg"], "pose.tilt_deg", 2, 2);
    for (double t : tilt)
      if (std::abs(t) >= 45.0) reader.Fail("pose.tilt_deg", "tilt must be within +-45 deg");
    out.tilt_x_rad = tilt[0] * kDegToRad;
    out.tilt_y_rad = tilt[1] * kDegToRad;
  }
  if (pose["decenter_mm"]) {
    const std::vector<double> decenter = reader.Numbers(pose["decenter_mm"], "pose.decenter_mm", 2, 2);
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
  const std::string profile = reader.Text(mirror, "profile", "mirror");
  const double rim = reader.Positive(mirror, "rim_radius", "mirror");
  if (profile == "sphere") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "A"});
    return Assemble(SphereProfile<double>{reader.Positive(mirror, "A", "mirror")}, lens, pose, rim);
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
    return Assemble(HyperboloidProfile<double>{reader.Positive(mirror, "A", "mirror"),
                                               reader.Positive(mirror, "B", "mirror")},
                    lens, pose, rim);
  }
  if (profile == "paraboloid") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "A"});
    return Assemble(ParaboloidProfile<double>{reader.Positive(mirror, "A", "mirror")}, lens, pose, rim);
  }
  if (profile == "tabulated") {
    reader.RejectUnknown(mirror, "mirror", {"profile", "rim_radius", "table"});
    std::filesystem::path table = reader.Text(mirror, "table", "mirror");
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

std::string ValidateSensorModel(const SensorModel& model) {
  return std::visit(
      [](const auto& m) -> std::string {
        using Model = std::decay_t<decltype(m)>;
        if (std::string why = m.mirror.CheckDomain(m.rim_radius_mm); !why.empty()) return "mirror: " + why;
        if (std::string why = m.lens.CheckDomain(); !why.empty()) return "camera: " + why;
        // The lens centre must sit below the mirror surface (outside the mirror body).
        const Eigen::Matrix3d rotation = m.pose.CameraFromMirrorRotation();
        const Eigen::Vector3d lens_in_mirror = -(rotation.transpose() * m.pose.CameraFromMirrorTranslation());
        const double r2 = lens_in_mirror.head<2>().squaredNorm();
        if (r2 < m.rim_radius_mm * m.rim_radius_mm &&
            !(lens_in_mirror.z() < m.mirror.EvaluateSag(r2).z))
          return "pose.m: the lens centre lies inside the mirror (m too small for this tilt/decenter)";
        if constexpr (!Model::kOrthographic) {
          // Unprojection inverts the radial distortion: it must be monotone over the image.
          const double corner_u = std::max(std::abs(m.lens.cx_px + 0.5), std::abs(m.image_width_px - 0.5 - m.lens.cx_px));
          const double corner_v = std::max(std::abs(m.lens.cy_px + 0.5), std::abs(m.image_height_px - 0.5 - m.lens.cy_px));
          const double rd_max = std::hypot(corner_u / m.lens.fx_px, corner_v / m.lens.fy_px);
          for (double r = 0.0;; r += 1e-3 * (1.0 + rd_max)) {
            const double r2d = r * r;
            if (1.0 + r2d * (3.0 * m.lens.k1 + 5.0 * r2d * m.lens.k2) <= 0.0)
              return "camera.k1: radial distortion (k1, k2) is not invertible within the image";
            if (r * (1.0 + r2d * (m.lens.k1 + r2d * m.lens.k2)) >= rd_max) break;
          }
        }
        return {};
      },
      model);
}

Sensor LoadSensorYaml(const std::string& path) {
  const FieldReader reader(path);
  if (!std::filesystem::exists(path)) reader.Fail("", "file not found");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::ParserException& error) {
    reader.Fail("line " + std::to_string(error.mark.line + 1), "malformed YAML: " + error.msg);
  } catch (const YAML::Exception& error) {
    reader.Fail("", std::string("cannot read: ") + error.what());
  }
  if (!root.IsMap()) reader.Fail("", "expected a map with camera, mirror and pose sections");
  reader.RejectUnknown(root, "(top level)", {"camera", "mirror", "pose"});
  try {
    const LensChoice lens = ReadCamera(reader, root);
    const MirrorPose<double> pose = ReadPose(reader, root);
    SensorModel model = ReadMirror(reader, root, lens, pose);
    if (std::string why = ValidateSensorModel(model); !why.empty()) throw InputError(path + ": " + why);
    return Sensor(std::move(model));
  } catch (const YAML::Exception& error) {
    reader.Fail("", std::string("unexpected YAML structure: ") + error.what());
  }
}

void SaveSensorYaml(const Sensor& sensor, const std::string& path) {
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
  WriteFileAtomically(path, [&](std::ostream& stream) { stream << out.c_str() << "\n"; });
}

}  // namespace omnical
