// omnical.Sensor: the run-time sensor (model/sensor.h) read from / written to sensor.yaml,
// built from or read as a parameter dict (the sensor file's sections), and projection of
// many points at once through the batch path with the GIL released.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

#include "model/input_error.h"
#include "model/io/sensor_yaml.h"
#include "model/sensor.h"
#include "tools/python/bindings.h"
#include "tools/python/py_common.h"

namespace omnical::python {
namespace {

using namespace pybind11::literals;

py::array_t<std::uint8_t> StatusArray(std::vector<ProjectionStatus>&& statuses) {
  static_assert(sizeof(ProjectionStatus) == 1, "statuses are handed over as uint8");
  auto* owned = new std::vector<ProjectionStatus>(std::move(statuses));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<ProjectionStatus>*>(p); });
  return py::array_t<std::uint8_t>({static_cast<py::ssize_t>(owned->size())},
                                   reinterpret_cast<const std::uint8_t*>(owned->data()), owner);
}

// A YAML scalar as the Python value it reads as: int, float, bool or str.
py::object ScalarValue(const std::string& text) {
  if (text == "true" || text == "false") return py::bool_(text == "true");
  char* end = nullptr;
  const long long whole = std::strtoll(text.c_str(), &end, 10);
  if (!text.empty() && *end == '\0') return py::int_(whole);
  const double number = std::strtod(text.c_str(), &end);
  if (!text.empty() && *end == '\0') return py::float_(number);
  return py::str(text);
}

py::object NodeValue(const YAML::Node& node) {
  if (node.IsMap()) {
    py::dict dict;
    for (const auto& entry : node) dict[py::str(entry.first.as<std::string>())] = NodeValue(entry.second);
    return std::move(dict);
  }
  if (node.IsSequence()) {
    py::list list;
    for (const auto& item : node) list.append(NodeValue(item));
    return std::move(list);
  }
  if (node.IsScalar()) return ScalarValue(node.Scalar());
  return py::none();
}

// A parameter dict back to YAML: numbers with Python's shortest round-trip text, NumPy
// scalars and arrays included; anything else refused naming its key.
void Emit(YAML::Emitter& out, const py::handle& value, const std::string& key, int depth = 0) {
  // The sensor file nests three levels (section, field, list); a self-containing list or
  // dict must not recurse forever.
  if (depth > 8) throw InputError("parameters: " + key + ": nested too deeply");
  if (py::isinstance<py::dict>(value)) {
    out << YAML::BeginMap;
    for (const auto& entry : py::reinterpret_borrow<py::dict>(value)) {
      const std::string name = py::str(entry.first);
      out << YAML::Key << name << YAML::Value;
      Emit(out, entry.second, key.empty() ? name : key + "." + name, depth + 1);
    }
    out << YAML::EndMap;
  } else if (py::isinstance<py::str>(value)) {
    out << std::string(py::str(value));
  } else if (py::isinstance<py::bool_>(value)) {
    out << (value.cast<bool>() ? "true" : "false");
  } else if (py::hasattr(value, "tolist") && !py::isinstance<py::float_>(value)) {
    Emit(out, value.attr("tolist")(), key, depth + 1);  // NumPy arrays and scalars
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    out << YAML::Flow << YAML::BeginSeq;
    for (const auto& item : value) Emit(out, item, key, depth + 1);
    out << YAML::EndSeq;
  } else if (py::isinstance<py::int_>(value)) {
    out << std::string(py::str(value));
  } else if (py::isinstance<py::float_>(value)) {
    const double number = value.cast<double>();
    if (!std::isfinite(number)) throw InputError("parameters: " + key + ": not a finite number");
    out << std::string(py::repr(value));
  } else {
    throw InputError("parameters: " + key + ": expected a number, a string, a list or a dict, got " +
                     std::string(py::str(py::type::of(value).attr("__name__"))));
  }
}

py::tuple Project(const Sensor& sensor, const py::handle& points) {
  const RowsArray rows = RowsOf(points, 3, "points");
  Eigen::Matrix2Xd pixels;
  std::vector<ProjectionStatus> statuses;
  {
    GilReleased release;
    sensor.ProjectBatch(AsColumns<3>(rows), &pixels, &statuses);
  }
  return py::make_tuple(RowsArrayOf<2>(std::move(pixels)), StatusArray(std::move(statuses)));
}

py::tuple Unproject(const Sensor& sensor, const py::handle& pixels) {
  const RowsArray rows = RowsOf(pixels, 2, "pixels");
  Eigen::Matrix3Xd origins, directions;
  std::vector<ProjectionStatus> statuses;
  {
    GilReleased release;
    sensor.UnprojectBatch(AsColumns<2>(rows), &origins, &directions, &statuses);
  }
  return py::make_tuple(RowsArrayOf<3>(std::move(origins)), RowsArrayOf<3>(std::move(directions)),
                        StatusArray(std::move(statuses)));
}

}  // namespace

void BindModel(py::module_& m) {
  py::list names;
  for (int code = 0; code <= static_cast<int>(ProjectionStatus::kInvalidInput); ++code)
    names.append(StatusName(static_cast<ProjectionStatus>(code)));
  m.attr("_STATUS_NAMES") = names;
  // The registry's choices (model/model_registry.h): what sensor files, calibrate(profile=)
  // and design_fit(profile=) accept.
  auto list_of = [](const std::vector<std::string>& names) {
    py::list out;
    for (const std::string& name : names) out.append(name);
    return out;
  };
  m.attr("PROFILES") = list_of(ProfileNames());
  m.attr("LENSES") = list_of(LensNames());
  m.attr("DESIGN_PROFILES") = list_of(DesignProfileNames());

  py::class_<Sensor>(m, "Sensor", R"(A catadioptric sensor: lens (pinhole or orthographic), mirror profile and
mirror pose, as in sensor.yaml (docs/file-formats.md "Sensor file").

Frames: camera frame (OpenCV convention, mm, z along the optical axis towards the
mirror); pixels with the centre of pixel (0, 0) at (0, 0).)")
      .def_static(
          "load", [](const py::object& path) { return LoadSensorYaml(PathOf(path)); }, "path"_a,
          "Reads a sensor file (YAML). Raises InputError naming the file and field.")
      .def_static("from_yaml", &ParseSensorYaml, "text"_a, "source"_a = "<string>",
                  "A sensor from YAML text; `source` names it in messages (and relative table paths resolve "
                  "against its directory).")
      .def_static(
          "from_parameters",
          [](const py::dict& parameters) {
            YAML::Emitter out;
            Emit(out, parameters, "");
            return ParseSensorYaml(out.c_str(), "parameters");
          },
          "parameters"_a,
          "A sensor from a dict shaped like the sensor file: {'camera': {...}, 'mirror': {...}, 'pose': {...}} "
          "(what `Sensor.parameters` returns). Raises InputError 'parameters: section: field: problem'.")
      .def(
          "save", [](const Sensor& sensor, const py::object& path) { SaveSensorYaml(sensor, PathOf(path)); }, "path"_a,
          "Writes the sensor file (atomically: a temporary file renamed into place).")
      .def("to_yaml", &SensorYamlText, "The text `save` writes.")
      .def_property_readonly(
          "parameters", [](const Sensor& sensor) { return NodeValue(YAML::Load(SensorYamlText(sensor))); },
          "The sensor file's sections as a dict (camera, mirror, pose); a new dict each time.")
      .def_property_readonly("profile", &Sensor::profile_name, "Mirror profile: sphere, polynomial, hyperboloid, ...")
      .def_property_readonly("lens", &Sensor::lens_name, "Lens model: pinhole or orthographic.")
      .def_property_readonly("rim_radius_mm", &Sensor::rim_radius_mm, "The mirror's rim radius (mm).")
      .def_property_readonly(
          "image_size", [](const Sensor& sensor) { return py::make_tuple(sensor.image_width_px(), sensor.image_height_px()); },
          "(width, height) in pixels.")
      .def_property_readonly("is_axial", &Sensor::is_axial, "True when the mirror axis is the optical axis (no tilt, no decenter).")
      .def("project", &Project, "points"_a,
           R"(Projects points (N, 3), camera frame, mm, to pixels.

Returns (pixels (N, 2) float64, status (N,) uint8): compare status with
ProjectionStatus (status == ProjectionStatus.OK); pixels of failed points are NaN.
NaN or infinite points give INVALID_INPUT, never an exception. Any real dtype and
strides are accepted (converted to float64); the GIL is released.)")
      .def("unproject", &Unproject, "pixels"_a,
           R"(The rays of pixels (N, 2): returns (origins (N, 3), directions (N, 3), status (N,)).

Origins are on the mirror (camera frame, mm), directions unit vectors; rows of failed
pixels are NaN.)")
      .def("__repr__", [](const Sensor& sensor) {
        return "<omnical.Sensor " + std::string(sensor.profile_name()) + " mirror, " + sensor.lens_name() + " lens, " +
               std::to_string(sensor.image_width_px()) + "x" + std::to_string(sensor.image_height_px()) + " px>";
      });
}

}  // namespace omnical::python
