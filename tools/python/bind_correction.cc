// The correction jobs in Python: remap tables (omnical.remap, remap_tables), the parallax
// report and a table's error at other distances (parallax, maps_error), unwarping
// (Unwarper, unwarp) and the best-fit central model (export_central). Each job takes a
// Sensor or the path of a sensor file (as the CLI's --sensor); each result's save() writes
// what the CLI command writes, through the same library writers and figure writers.
#include <pybind11/stl.h>

#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "calib/report/correction_figures.h"
#include "correction/central_export.h"
#include "correction/maps_error_report.h"
#include "correction/parallax_report.h"
#include "correction/remap_outputs.h"
#include "correction/unwarp.h"
#include "model/input_error.h"
#include "model/io/sensor_yaml.h"
#include "tools/python/bindings.h"
#include "tools/python/py_common.h"
#include "tools/python/py_image.h"

namespace omnical::python {
namespace {

using namespace pybind11::literals;

// A job's sensor argument: an omnical.Sensor, or a sensor file's path. From a path, the
// file's name and text go into the files the result saves, as the CLI writes --sensor's;
// from a Sensor, no name and the text Sensor.to_yaml() gives.
class SensorArgument {
 public:
  explicit SensorArgument(const py::handle& sensor) {
    if (py::isinstance<Sensor>(sensor)) {
      borrowed_ = &sensor.cast<const Sensor&>();
      source_.yaml = SensorYamlText(*borrowed_);
      return;
    }
    source_.file = PathOf(sensor);
    loaded_.emplace(LoadSensorYaml(source_.file));
    std::stringstream text;
    text << std::ifstream(source_.file).rdbuf();
    source_.yaml = text.str();
  }
  const Sensor& sensor() const { return loaded_ ? *loaded_ : *borrowed_; }
  const SensorSource& source() const { return source_; }

 private:
  std::optional<Sensor> loaded_;
  const Sensor* borrowed_ = nullptr;
  SensorSource source_;
};

// What save() names as the sensor: `sensor_path` when given (read and checked as the CLI
// reads --sensor), else the job's own.
SensorSource SourceFor(const py::object& sensor_path, const SensorSource& job_source) {
  if (sensor_path.is_none()) return job_source;
  return SensorArgument(py::str(PathOf(sensor_path))).source();
}

template <typename Value>
py::array_t<Value> CopyArray(const std::vector<Value>& values) {
  return py::array_t<Value>(static_cast<py::ssize_t>(values.size()), values.data());
}

// A row-major float table owned by a result, as an (H, W) array that keeps the result alive.
py::array_t<float> TableView(const std::vector<float>& values, int width, int height, const py::handle& owner) {
  return py::array_t<float>({static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width)}, values.data(), owner);
}

// --- view requests ---------------------------------------------------------------------
// Every ViewRequest field is a keyword of the same name (so the library's "field: problem"
// messages name the keyword); the list is shared by remap() and Unwarper.from_view().
#define OMNICAL_VIEW_PARAMS                                                                                     \
  const std::string &view, const py::object &size, double azimuth0_deg,                                         \
      const std::optional<std::vector<double>>&elevation_deg, double pan_deg, double tilt_deg, double roll_deg, \
      double hfov_deg, std::optional<double> omega_max_deg, std::optional<double> distance_mm,                  \
      std::optional<double> n, bool infinity, const std::string &surface,                                       \
      const std::optional<std::vector<double>>&plane_normal, std::optional<double> v0_mm, int threads, bool per_pixel
#define OMNICAL_VIEW_FIELDS                                                                                      \
  view, size, azimuth0_deg, elevation_deg, pan_deg, tilt_deg, roll_deg, hfov_deg, omega_max_deg, distance_mm, n, \
      infinity, surface, plane_normal, v0_mm, threads, per_pixel
#define OMNICAL_VIEW_ARGS                                                                                         \
  "view"_a = "panorama", py::kw_only(), "size"_a = py::none(), "azimuth0_deg"_a = 180.0,                          \
  "elevation_deg"_a = py::none(), "pan_deg"_a = 0.0, "tilt_deg"_a = 0.0, "roll_deg"_a = 0.0, "hfov_deg"_a = 60.0, \
  "omega_max_deg"_a = py::none(), "distance_mm"_a = py::none(), "n"_a = py::none(), "infinity"_a = false,         \
  "surface"_a = "sphere", "plane_normal"_a = py::none(), "v0_mm"_a = py::none(), "threads"_a = 0,                 \
  "per_pixel"_a = false

// "WxH" as given, or (W, H).
std::string SizeText(const py::object& size) {
  if (size.is_none()) return "";
  if (py::isinstance<py::str>(size)) return size.cast<std::string>();
  try {
    const auto [width, height] = size.cast<std::pair<int, int>>();
    return std::to_string(width) + "x" + std::to_string(height);
  } catch (const py::cast_error&) {
    throw InputError("size: expected 'WxH' or (width, height), got " + std::string(py::str(py::repr(size))));
  }
}

ViewRequest ViewOf(OMNICAL_VIEW_PARAMS) {
  ViewRequest request;
  request.view = view, request.size = SizeText(size), request.azimuth0_deg = azimuth0_deg;
  request.elevation_deg = elevation_deg.value_or(std::vector<double>{});
  request.pan_deg = pan_deg, request.tilt_deg = tilt_deg, request.roll_deg = roll_deg, request.hfov_deg = hfov_deg;
  request.omega_max_deg = omega_max_deg, request.distance_mm = distance_mm, request.n = n, request.infinity = infinity;
  request.surface = surface, request.plane_normal = plane_normal.value_or(std::vector<double>{});
  request.v0_mm = v0_mm, request.threads = threads, request.per_pixel = per_pixel;
  return request;
}

// The resolved request as remap()'s keywords: remap(sensor, **settings) makes the same table.
py::dict SettingsOf(const RemapSettings& settings) {
  const VirtualScreen& s = settings.screen;
  const ObjectSurface& o = settings.surface;
  py::dict d("view"_a = ScreenTypeName(s.type),
             "size"_a = std::to_string(s.width_px) + "x" + std::to_string(s.height_px));
  if (s.type == VirtualScreen::Type::kPanorama || s.type == VirtualScreen::Type::kLonLat) {
    d["azimuth0_deg"] = s.azimuth0_deg;
    d["elevation_deg"] = py::make_tuple(s.elevation_top_deg, s.elevation_bottom_deg);
  } else if (s.type == VirtualScreen::Type::kPerspective) {
    d["pan_deg"] = s.pan_deg, d["tilt_deg"] = s.tilt_deg, d["roll_deg"] = s.roll_deg, d["hfov_deg"] = s.hfov_deg;
  } else {
    d["omega_max_deg"] = s.omega_max_deg;
  }
  if (o.kind == ObjectSurface::Kind::kInfinity) {
    d["infinity"] = true;
  } else {
    d["distance_mm"] = o.distance_mm, d["surface"] = SurfaceKindName(o.kind);
    if (o.kind == ObjectSurface::Kind::kPlane)
      d["plane_normal"] = py::make_tuple(o.plane_normal.x(), o.plane_normal.y(), o.plane_normal.z());
  }
  d["v0_mm"] = settings.v0_mm, d["threads"] = settings.threads, d["per_pixel"] = !settings.allow_shortcuts;
  return d;
}

// --- remap -----------------------------------------------------------------------------
struct PyRemap {
  RemapResult result;
  SensorSource sensor;
};

PyRemap Remap(const py::object& sensor_argument, OMNICAL_VIEW_PARAMS, const py::object& progress) {
  const SensorArgument sensor(sensor_argument);
  RemapOptions options;
  options.view = ViewOf(OMNICAL_VIEW_FIELDS);
  options.progress = ForwardProgress(progress);
  return {RunReleased([&] { return BuildRemap(sensor.sensor(), options); }), sensor.source()};
}

std::vector<MapFormat> FormatsOf(const py::object& formats) {
  const std::vector<std::string> names = py::isinstance<py::str>(formats)
                                             ? std::vector<std::string>{formats.cast<std::string>()}
                                             : formats.cast<std::vector<std::string>>();
  std::vector<MapFormat> parsed;
  for (const std::string& name : names) {
    const auto format = ParseMapFormat(name);
    if (!format) throw InputError("formats: unknown '" + name + "' (opencv, ffmpeg, npy)");
    parsed.push_back(*format);
  }
  return parsed;
}

void SaveRemap(const PyRemap& remap, const py::object& out_dir, const py::object& formats,
               const py::object& sensor_path) {
  const std::string dir = PathOf(out_dir);
  const std::vector<MapFormat> parsed = FormatsOf(formats);
  const SensorSource source = SourceFor(sensor_path, remap.sensor);
  GilReleased release;
  WriteRemapOutputs(dir, remap.result, parsed, source);
  WriteRemapFigures(dir, remap.result);
}

// --- unwarp ----------------------------------------------------------------------------
Interpolation InterpolationOf(const std::string& name) {
  const auto interpolation = ParseInterpolation(name);
  if (!interpolation) throw InputError("interpolation: unknown '" + name + "' (nearest, linear, cubic)");
  return *interpolation;
}

// (map_x, map_y): two (H, W) arrays of the same shape, any real dtype (as float32).
RemapTable TableOf(const py::handle& maps) {
  const char* expected = "maps: expected a remap output directory, a RemapResult or (map_x, map_y) (H, W) arrays";
  if (!py::isinstance<py::sequence>(maps) || py::len(maps) != 2) throw InputError(expected);
  using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
  const Floats map_x = Floats::ensure(maps[py::int_(0)]), map_y = Floats::ensure(maps[py::int_(1)]);
  if (!map_x || !map_y || map_x.ndim() != 2 || map_y.ndim() != 2 || map_x.shape(0) != map_y.shape(0) ||
      map_x.shape(1) != map_y.shape(1) || map_x.size() == 0) {
    PyErr_Clear();
    throw InputError(expected);
  }
  RemapTable table;
  table.height = static_cast<int>(map_x.shape(0)), table.width = static_cast<int>(map_x.shape(1));
  table.map_x.assign(map_x.data(), map_x.data() + map_x.size());
  table.map_y.assign(map_y.data(), map_y.data() + map_y.size());
  return table;
}

py::array Apply(const Unwarper& unwarper, const py::object& image) {
  const cv::Mat frame = MatOf(image, "image");
  cv::Mat unwarped;
  {
    GilReleased release;
    unwarped = unwarper.Apply(frame, "image");
  }
  return ArrayOf(unwarped);
}

Unwarper UnwarperOf(const py::object& maps, const py::object& image, Interpolation interpolation) {
  if (py::isinstance<PyRemap>(maps)) {
    const RemapResult& result = maps.cast<const PyRemap&>().result;
    return Unwarper(result.table, result.sensor_width_px, result.sensor_height_px, interpolation);
  }
  if (py::isinstance<py::str>(maps) || py::hasattr(maps, "__fspath__"))
    return Unwarper::FromMaps(PathOf(maps), interpolation);
  const cv::Mat frame = MatOf(image, "image");  // a bare table fits any image of its sensor's size
  return Unwarper(TableOf(maps), frame.cols, frame.rows, interpolation);
}

// Frames from an iterable through UnwarpFrames (its checks, progress stage "unwarp"),
// each unwarped frame handed to write(frame); the GIL is held only to read and write.
// UnwarpFrames reads on one thread and writes on another, a few frames ahead of the
// remap: each frame is copied out of its array, which the iterator may reuse or free.
// Neither thread takes the GIL once the interpreter is shutting down (a daemon thread's
// call): taking it then would end the thread inside the library.
long ApplyFrames(const Unwarper& unwarper, const py::object& frames, const py::object& write, long total,
                 const std::string& source, const py::object& progress) {
  const py::iterator iterator = py::iter(frames);
  const ProgressCallback callback = ForwardProgress(progress);
  auto read = [&](cv::Mat* frame) {
    if (Finalizing()) throw Cancelled("unwarp");
    py::gil_scoped_acquire gil;
    const auto current = py::reinterpret_steal<py::object>(PyIter_Next(iterator.ptr()));
    if (!current) {
      if (PyErr_Occurred()) throw py::error_already_set();
      return false;
    }
    *frame = MatOf(current, source.c_str()).clone();
    return true;
  };
  auto emit = [&](const cv::Mat& unwarped) {
    if (Finalizing()) throw Cancelled("unwarp");
    py::gil_scoped_acquire gil;
    write(ArrayOf(unwarped));
  };
  return RunReleased([&] { return UnwarpFrames(unwarper, read, emit, total, source, callback); });
}

// --- parallax, maps error, central export -----------------------------------------------
struct PyParallax {
  ParallaxResult result;
  std::string sensor_file;
};

struct PyCentral {
  CentralExportResult result;
  std::string sensor_file;
};

py::array_t<double> MatrixArray(const Eigen::Matrix3d& matrix) {
  py::array_t<double> array(std::vector<py::ssize_t>{3, 3});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) array.mutable_at(r, c) = matrix(r, c);
  return array;
}

py::dict CentralParameters(const CentralExportResult& result) {
  if (result.model == CentralModelKind::kMei) {
    const MeiModel& m = result.mei;
    return py::dict("fx"_a = m.fx, "fy"_a = m.fy, "cx"_a = m.cx, "cy"_a = m.cy, "skew"_a = m.skew, "xi"_a = m.xi,
                    "k1"_a = m.k1, "k2"_a = m.k2, "p1"_a = m.p1, "p2"_a = m.p2);
  }
  const OCamModel& o = result.ocam;
  return py::dict("pol"_a = CopyArray(o.pol), "invpol"_a = CopyArray(o.invpol), "xc_row"_a = o.xc_row,
                  "yc_col"_a = o.yc_col, "c"_a = o.c, "d"_a = o.d, "e"_a = o.e);
}

template <typename Point>
py::array_t<double> PointRows(const std::vector<Point>& points) {
  constexpr int K = Point::RowsAtCompileTime;
  Eigen::Matrix<double, K, Eigen::Dynamic> columns(K, points.size());
  for (size_t i = 0; i < points.size(); ++i) columns.col(static_cast<Eigen::Index>(i)) = points[i];
  return RowsArrayOf<K>(std::move(columns));
}

}  // namespace

void BindCorrection(py::module_& m) {
  // remap ------------------------------------------------------------------------------
  py::class_<PyRemap>(m, "RemapResult",
                      R"(A remap table from omnical.remap(): for every output pixel the omni-image pixel to
sample, exact for objects on the chosen surface (what `omnical remap` computes).)")
      .def_property_readonly(
          "map_x",
          [](const py::object& self) {
            const RemapTable& t = self.cast<const PyRemap&>().result.table;
            return TableView(t.map_x, t.width, t.height, self);
          },
          "Omni-image column to sample, float32 (H, W), -1 where the output pixel sees no mirror: "
          "cv2.remap(image, map_x, map_y, cv2.INTER_LINEAR). A view of the result's table.")
      .def_property_readonly(
          "map_y",
          [](const py::object& self) {
            const RemapTable& t = self.cast<const PyRemap&>().result.table;
            return TableView(t.map_y, t.width, t.height, self);
          },
          "Omni-image row to sample, float32 (H, W), -1 where the output pixel sees no mirror.")
      .def_property_readonly(
          "size", [](const PyRemap& r) { return py::make_tuple(r.result.table.width, r.result.table.height); },
          "(width, height) of the output, px.")
      .def_property_readonly(
          "exactness_px", [](const PyRemap& r) { return r.result.exactness_px; },
          "Largest difference between table entries and fresh exact projections of their object points "
          "(4000 random output pixels), px.")
      .def_property_readonly(
          "valid_fraction", [](const PyRemap& r) { return r.result.valid_fraction; },
          "Fraction of the output pixels that see the mirror.")
      .def_property_readonly(
          "v0_mm", [](const PyRemap& r) { return r.result.settings.v0_mm; },
          "The viewpoint V0 (z on the mirror axis, mm, mirror frame).")
      .def_property_readonly(
          "v0_searched", [](const PyRemap& r) { return r.result.v0_searched; },
          "True when V0 was chosen (least worst error at the distance), not given.")
      .def_property_readonly(
          "method",
          [](const PyRemap& r) {
            const RemapTable& t = r.result.table;
            return t.used_axial_symmetry         ? "axial symmetry"
                   : t.interpolation_step_px > 0 ? "interpolated grid"
                                                 : "per pixel";
          },
          "How the table was built: 'axial symmetry', 'interpolated grid' (< 0.01 px) or 'per pixel'.")
      .def_property_readonly(
          "generation_seconds", [](const PyRemap& r) { return r.result.generation_seconds; },
          "Time spent building the table, s.")
      .def_property_readonly(
          "error_at_other_distances",
          [](const PyRemap& r) {
            py::list rows;
            for (const RemapErrorAtDistance& e : r.result.error_at_other_distances)
              rows.append(py::make_tuple(e.n, e.distance_mm, e.stats.max_px, e.stats.rms_px, e.stats.samples));
            return rows;
          },
          "How wrong the table is for objects elsewhere: [(n, distance_mm, max_px, rms_px, samples), ...] at n = 1.5, "
          "2, "
          "3, 5, 7, 10, 20, 40, 100 rim radii and inf (infinity); output px, as maps.json has them.")
      .def_property_readonly(
          "settings", [](const PyRemap& r) { return SettingsOf(r.result.settings); },
          "The resolved view as remap() keywords (defaults filled in): remap(sensor, **settings) "
          "makes the same table.")
      .def("save", &SaveRemap, "out_dir"_a, "formats"_a = py::make_tuple("opencv"), "sensor_path"_a = py::none(),
           R"(Writes what `omnical remap --out OUT_DIR --format ...` writes: the table in each of
`formats` ("opencv": maps.yml.gz + maps_fixed.yml.gz, "ffmpeg": xmap.pgm + ymap.pgm,
"npy": map_x.npy + map_y.npy), maps.json and remap_error.png. maps.json names the sensor
as `sensor_path` (default: the path remap() read, or none for a Sensor object).)");

  m.def("remap", &Remap, "sensor"_a, OMNICAL_VIEW_ARGS, "progress"_a = py::none(),
        R"(A remap table to a virtual screen, exact for objects at a known distance (`omnical remap`).

sensor: an omnical.Sensor or a sensor file's path. view: panorama, lonlat, perspective or
equiangular; size: "WxH" or (W, H) (default per view). panorama/lonlat: azimuth0_deg,
elevation_deg=(top, bottom); perspective: pan_deg, tilt_deg, roll_deg, hfov_deg;
equiangular: omega_max_deg. Objects: exactly one of distance_mm, n (mirror rim radii) or
infinity=True, on surface sphere (around V0), cylinder or plane (plane_normal). v0_mm:
the viewpoint (default: least worst error). threads: 0 = all cores. per_pixel: no
interpolated grid. progress(stage, done, total): stages "remap table", "remap error".
Returns a RemapResult; InputError names the keyword ("size: '12' is not WxH ...").)");

  m.def(
      "remap_tables",
      [m](const py::object& sensor, const py::object& screen, const py::object& surface, const py::kwargs& options) {
        const py::object result = m.attr("remap")(sensor, screen, "surface"_a = surface, **options);
        return py::make_tuple(result.attr("map_x"), result.attr("map_y"));
      },
      "sensor"_a, "screen"_a = "panorama", "surface"_a = "sphere",
      "remap(sensor, view=screen, surface=surface, **options) as (map_x, map_y), float32 (H, W) arrays for cv2.remap.");

  // unwarp -----------------------------------------------------------------------------
  py::class_<Unwarper>(m, "Unwarper", R"(Omni images through a remap table to the virtual screen with cv::remap, as
`omnical unwarp` does (fixed-point maps for linear and cubic, float maps for nearest).)")
      .def_static(
          "from_maps",
          [](const py::object& maps_dir, const std::string& interpolation, const py::object& sensor) {
            if (sensor.is_none()) return Unwarper::FromMaps(PathOf(maps_dir), InterpolationOf(interpolation));
            const SensorArgument given(sensor);
            return Unwarper::FromMaps(PathOf(maps_dir), InterpolationOf(interpolation), &given.sensor(),
                                      given.source().file);
          },
          "maps_dir"_a, py::kw_only(), "interpolation"_a = "linear", "sensor"_a = py::none(),
          "From a directory written by remap (maps.json + maps.yml.gz). `sensor`, when given, must have the maps' "
          "image "
          "size. interpolation: nearest, linear or cubic.")
      .def_static(
          "from_view",
          [](const py::object& sensor_argument, OMNICAL_VIEW_PARAMS, const std::string& interpolation,
             const py::object& progress) {
            const SensorArgument sensor(sensor_argument);
            const ViewRequest request = ViewOf(OMNICAL_VIEW_FIELDS);
            const Interpolation chosen = InterpolationOf(interpolation);
            const ProgressCallback callback = ForwardProgress(progress);
            return RunReleased([&] { return Unwarper::FromView(sensor.sensor(), request, chosen, callback); });
          },
          "sensor"_a, OMNICAL_VIEW_ARGS, "interpolation"_a = "linear", "progress"_a = py::none(),
          "A table made now from remap()'s keywords (progress stage 'remap table').")
      .def_static(
          "from_tables",
          [](const py::object& map_x, const py::object& map_y, const std::pair<int, int>& image_size,
             const std::string& interpolation) {
            return Unwarper(TableOf(py::make_tuple(map_x, map_y)), image_size.first, image_size.second,
                            InterpolationOf(interpolation));
          },
          "map_x"_a, "map_y"_a, "image_size"_a, py::kw_only(), "interpolation"_a = "linear",
          "From (H, W) tables (e.g. RemapResult.map_x/map_y) for images of image_size = (width, height).")
      .def("apply", &Apply, "image"_a,
           "The image (uint8 (H, W) grey or (H, W, 3|4) BGR, the sensor's size) unwarped: a uint8 array of the output "
           "size. Other dtypes raise InputError; any strides are accepted. The GIL is released.")
      .def("apply_frames", &ApplyFrames, "frames"_a, "write"_a, py::kw_only(), "total"_a = 0, "source"_a = "frames",
           "progress"_a = py::none(),
           R"(Every frame of an iterable (e.g. read from cv2.VideoCapture) unwarped and passed to
write(frame); returns the number of frames. InputError naming `source` when there are no
frames or one has the wrong size. progress stage "unwarp" against `total` (0: unknown).
Reading, unwarping and writing overlap: the iterable is advanced on one worker thread
and write is called on another (each frame copied when read, written in order), so an
iterator bound to the calling thread (e.g. a sqlite3 cursor) cannot be used, Ctrl-C
waits for a blocked iterator to yield, and on an error up to a few frames already read
are dropped.)")
      .def_property_readonly(
          "size", [](const Unwarper& u) { return py::make_tuple(u.width_px(), u.height_px()); },
          "(width, height) of the output, px.");

  m.def(
      "unwarp",
      [](const py::object& image, const py::object& maps, const std::string& interpolation) {
        return Apply(UnwarperOf(maps, image, InterpolationOf(interpolation)), image);
      },
      "image"_a, "maps"_a, py::kw_only(), "interpolation"_a = "linear",
      R"(The image through a remap table: `maps` is a remap output directory (path), a
RemapResult or (map_x, map_y). image: uint8 grey or BGR of the sensor's size. For many
frames build an Unwarper once.)");

  // parallax ---------------------------------------------------------------------------
  py::class_<PyParallax>(m, "ParallaxResult",
                         R"(The viewpoint-distribution error of a central virtual projector at V0 (seed Eq. 23)
for objects D mm away: the curve over the field and the map over the omni image.)")
      .def_property_readonly(
          "distance_mm", [](const PyParallax& p) { return p.result.distance_mm; }, "Object distance, mm.")
      .def_property_readonly(
          "n", [](const PyParallax& p) { return p.result.n; }, "Object distance in mirror rim radii.")
      .def_property_readonly(
          "v0_mm", [](const PyParallax& p) { return p.result.v0_mm; }, "V0, z on the mirror axis (mm).")
      .def_property_readonly(
          "v0_searched", [](const PyParallax& p) { return p.result.v0_searched; },
          "True when V0 minimises the worst pixel error (not given).")
      .def_property_readonly(
          "axial", [](const PyParallax& p) { return p.result.axial; },
          "False: the curve is the aligned counterpart's, the map the exact sensor's.")
      .def_property_readonly(
          "omega_deg", [](const PyParallax& p) { return CopyArray(p.result.curve.omega_deg); },
          "Curve: each sample's Omega (deg), float64 (samples,).")
      .def_property_readonly(
          "x_mm", [](const PyParallax& p) { return CopyArray(p.result.curve.x_mm); },
          "Curve: each sample's radius on the mirror, mm.")
      .def_property_readonly(
          "error_deg", [](const PyParallax& p) { return CopyArray(p.result.curve.error_deg); },
          "Curve: the angle error, deg (signed).")
      .def_property_readonly(
          "error_px", [](const PyParallax& p) { return CopyArray(p.result.curve.error_px); },
          "Curve: the error in omni-image px (signed).")
      .def_property_readonly(
          "max_abs_error_px", [](const PyParallax& p) { return p.result.curve.max_abs_error_px; },
          "Largest |error_px| of the curve.")
      .def_property_readonly(
          "max_abs_error_deg", [](const PyParallax& p) { return p.result.curve.max_abs_error_deg; },
          "Largest |error_deg| of the curve.")
      .def_property_readonly(
          "error_map",
          [](const py::object& self) {
            const ParallaxMap& map = self.cast<const PyParallax&>().result.map;
            return TableView(map.error_px, map.width, map.height, self);
          },
          "The error over the omni image, float32 (H, W) px, NaN where the pixel sees no mirror.")
      .def_property_readonly(
          "map_max_abs_error_px", [](const PyParallax& p) { return p.result.map.max_abs_error_px; },
          "Largest |error| of the map, px.")
      .def(
          "save",
          [](const PyParallax& p, const py::object& out_dir, const py::object& sensor_path) {
            const std::string dir = PathOf(out_dir);
            const std::string sensor_file = sensor_path.is_none() ? p.sensor_file : PathOf(sensor_path);
            GilReleased release;
            WriteParallaxFiles(dir, p.result, sensor_file);
            WriteParallaxFigures(dir, p.result);
          },
          "out_dir"_a, "sensor_path"_a = py::none(),
          "Writes what `omnical parallax` writes: parallax.csv, parallax.json (naming the sensor as `sensor_path`, "
          "default the path parallax() read), parallax.png and error_map.png.");

  m.def(
      "parallax",
      [](const py::object& sensor_argument, std::optional<double> n, std::optional<double> distance_mm,
         std::optional<double> v0_mm, int samples, int threads, const py::object& progress) {
        const SensorArgument sensor(sensor_argument);
        ParallaxOptions options;
        options.n = n, options.distance_mm = distance_mm, options.v0_mm = v0_mm, options.samples = samples;
        options.threads = threads, options.progress = ForwardProgress(progress);
        return PyParallax{RunReleased([&] { return ParallaxReport(sensor.sensor(), options); }), sensor.source().file};
      },
      "sensor"_a, py::kw_only(), "n"_a = py::none(), "distance_mm"_a = py::none(), "v0_mm"_a = py::none(),
      "samples"_a = ParallaxOptions{}.samples, "threads"_a = 0, "progress"_a = py::none(),
      R"(The parallax report (`omnical parallax`): objects at n rim radii or distance_mm from the
mirror (exactly one), V0 given or the best; samples over the mirror radius (10..100000);
progress stage "parallax map". Returns a ParallaxResult.)");

  py::class_<MapsErrorResult>(m, "MapsErrorResult",
                              "How wrong a remap table on disk is for objects at other distances.")
      .def_property_readonly(
          "maps_dir", [](const MapsErrorResult& r) { return r.maps.dir; }, "The maps directory.")
      .def_property_readonly(
          "made_for", [](const MapsErrorResult& r) { return r.made_for; },
          "What the table is exact for: 'infinity' or 'a sphere at n = 7.000'.")
      .def_property_readonly(
          "v0_mm", [](const MapsErrorResult& r) { return r.maps.settings.v0_mm; }, "The table's V0, mm.")
      .def_property_readonly(
          "rim_radius_mm", [](const MapsErrorResult& r) { return r.rim_radius_mm; },
          "Rim radius of the sensor evaluated, mm.")
      .def_property_readonly(
          "errors",
          [](const MapsErrorResult& r) {
            py::list rows;
            for (const RemapErrorAtDistance& e : r.errors)
              rows.append(py::make_tuple(e.n, e.distance_mm, e.stats.max_px, e.stats.rms_px, e.stats.samples));
            return rows;
          },
          "[(n, distance_mm, max_px, rms_px, samples), ...], ascending n, inf (infinity) last; output px.")
      .def("max_px_at", &MapsErrorResult::MaxPxAtN, "n"_a,
           "The largest error at n (one of the sweep's values), or NaN.")
      .def(
          "save",
          [](const MapsErrorResult& r, const py::object& out_dir) {
            const std::string dir = PathOf(out_dir);
            GilReleased release;
            WriteMapsErrorFiles(dir, r);
            WriteMapsErrorFigures(dir, r);
          },
          "out_dir"_a,
          "Writes what `omnical parallax --maps` writes: maps-error.csv, maps-error.json, maps-error.png.");

  m.def(
      "maps_error",
      [](const py::object& maps_dir, const py::object& sensor, int threads, const py::object& progress) {
        const MapsDescription maps = ReadMapsDescription(PathOf(maps_dir));
        const std::optional<SensorArgument> given =
            sensor.is_none() ? std::nullopt : std::optional<SensorArgument>(sensor);
        const std::optional<Sensor> own = given ? std::nullopt : std::optional<Sensor>(SensorOfMaps(maps));
        MapsErrorOptions options;
        options.threads = threads, options.progress = ForwardProgress(progress);
        return RunReleased([&] { return MapsErrorReport(maps, given ? given->sensor() : *own, options); });
      },
      "maps_dir"_a, "sensor"_a = py::none(), py::kw_only(), "threads"_a = 0, "progress"_a = py::none(),
      R"(A remap table's error at other object distances (`omnical parallax --maps DIR`):
`sensor` (Sensor or path) instead of the one stored in maps.json. progress stage
"remap error". Returns a MapsErrorResult.)");

  // export-central ---------------------------------------------------------------------
  py::class_<PyCentral>(m, "CentralExportResult",
                        "The best-fit central model (Mei or OCamCalib) of a sensor and its error.")
      .def_property_readonly(
          "model", [](const PyCentral& c) { return CentralModelKindName(c.result.model); }, "mei or ocamcalib.")
      .def_property_readonly(
          "fitted_for", [](const PyCentral& c) { return c.result.FittedForText(); },
          "'objects at infinity' or 'objects on a sphere of D mm around V0'.")
      .def_property_readonly(
          "v0_mm", [](const PyCentral& c) { return c.result.v0_mm; }, "The model's viewpoint V0, mm.")
      .def_property_readonly(
          "parameters", [](const PyCentral& c) { return CentralParameters(c.result); },
          "The fitted parameters as central.json has them (mei: fx, fy, cx, cy, skew, xi, k1, k2, p1, "
          "p2; ocamcalib: pol, invpol, xc_row, yc_col, c, d, e).")
      .def_property_readonly(
          "central_from_mirror",
          [](const PyCentral& c) {
            return MatrixArray(c.result.model == CentralModelKind::kMei ? c.result.mei.central_from_mirror
                                                                        : c.result.ocam.central_from_mirror);
          },
          "3x3: point_in_model = central_from_mirror @ (point_in_mirror - (0, 0, v0_mm)).")
      .def_property_readonly(
          "rms_px", [](const PyCentral& c) { return c.result.error.rms_px; }, "RMS error over the samples, omni px.")
      .def_property_readonly(
          "max_px", [](const PyCentral& c) { return c.result.error.max_px; }, "Largest error, omni px.")
      .def_property_readonly(
          "pixels", [](const PyCentral& c) { return PointRows(c.result.samples.pixels); },
          "The field samples' omni pixels, (N, 2).")
      .def_property_readonly(
          "points_in_mirror", [](const PyCentral& c) { return PointRows(c.result.samples.points_in_mirror); },
          "Their object points on the fitted surface, (N, 3) mm, mirror frame.")
      .def_property_readonly(
          "omega_deg", [](const PyCentral& c) { return CopyArray(c.result.error.omega_deg); },
          "Each sample's ray angle from the mirror axis, deg.")
      .def_property_readonly(
          "error_px", [](const PyCentral& c) { return CopyArray(c.result.error.error_px); },
          "Each sample's model error, omni px.")
      .def_property_readonly(
          "error_at_other_distances",
          [](const PyCentral& c) {
            py::list rows;
            for (const CentralErrorAtDistance& e : c.result.error_at_other_distances)
              rows.append(py::make_tuple(e.n, e.distance_mm, e.rms_px, e.max_px));
            return rows;
          },
          "[(n, distance_mm, rms_px, max_px), ...] at n = 2 .. 100 and inf.")
      .def(
          "save",
          [](const PyCentral& c, const py::object& out_dir, const py::object& sensor_path) {
            const std::string dir = PathOf(out_dir);
            const std::string sensor_file = sensor_path.is_none() ? c.sensor_file : PathOf(sensor_path);
            GilReleased release;
            WriteCentralExport(dir, c.result, sensor_file);
            WriteCentralExportFigures(dir, c.result);
          },
          "out_dir"_a, "sensor_path"_a = py::none(),
          "Writes what `omnical export-central` writes: omnidir.yml or calib_results.txt, central.json, "
          "central_error.csv and central_error.png.");

  m.def(
      "export_central",
      [](const py::object& sensor_argument, const std::string& model, std::optional<double> distance_mm,
         std::optional<double> n, std::optional<double> v0_mm, double step_px, const py::object& progress) {
        const SensorArgument sensor(sensor_argument);
        CentralExportOptions options;
        const auto kind = ParseCentralModelKind(model);
        if (!kind) throw InputError("model: unknown '" + model + "' (mei, ocamcalib)");
        options.model = *kind, options.distance_mm = distance_mm, options.n = n, options.v0_mm = v0_mm;
        options.step_px = step_px, options.progress = ForwardProgress(progress);
        return PyCentral{RunReleased([&] { return ExportCentral(sensor.sensor(), options); }), sensor.source().file};
      },
      "sensor"_a, py::kw_only(), "model"_a = "mei", "distance_mm"_a = py::none(), "n"_a = py::none(),
      "v0_mm"_a = py::none(), "step_px"_a = CentralExportOptions{}.step_px, "progress"_a = py::none(),
      R"(The best-fit central model (`omnical export-central`): model "mei" (cv::omnidir) or
"ocamcalib"; objects on a sphere of distance_mm or n rim radii around V0 (neither:
infinity); V0 given or the best; field grid step_px (omni px). Progress stage
"export-central". Returns a CentralExportResult.)");
}

}  // namespace omnical::python
