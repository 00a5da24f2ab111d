// Synthetic scenes and mirror design: omnical.Scene and render (calib/synthetic), the design
// jobs design_ode and design_fit, and characterize (model/design). Each result's save()
// writes what the matching CLI command writes, through the same library writers and
// calib/report figures (tools/cmd_render.cc, cmd_design.cc, cmd_design_fit.cc,
// cmd_characterize.cc).
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "calib/report/design_figures.h"
#include "calib/report/optics_figures.h"
#include "calib/synthetic/render_scene.h"
#include "calib/synthetic/scene.h"
#include "model/design/characterize.h"
#include "model/design/design_files.h"
#include "model/design/design_fit_job.h"
#include "model/design/design_ode_job.h"
#include "model/design/design_spec_yaml.h"
#include "model/input_error.h"
#include "model/model_registry.h"
#include "model/io/atomic_write.h"
#include "model/io/sensor_yaml.h"
#include "tools/python/bindings.h"
#include "tools/python/py_common.h"
#include "tools/python/py_image.h"

namespace omnical::python {
namespace {

using namespace pybind11::literals;
constexpr double kDeg = 180.0 / M_PI;

py::array_t<double> PoseArray(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation_mm) {
  py::array_t<double> pose({4, 4});
  auto p = pose.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) p(r, c) = r == 3 ? (c == 3 ? 1.0 : 0.0) : c == 3 ? translation_mm[r] : rotation(r, c);
  return pose;
}

// Columns of a table of `rows` rows as float64 arrays: column(i) -> value.
template <typename Value>
py::array_t<double> Column(size_t rows, Value&& value) {
  std::vector<double> column(rows);
  for (size_t i = 0; i < rows; ++i) column[i] = value(i);
  return VectorArray(std::move(column));
}

// A profile table as profile.csv holds it: (N, 3) radius_mm, sag_mm, slope.
py::array_t<double> ProfileArray(const ProfileTable& table) {
  Eigen::Matrix3Xd rows(3, table.radius_mm.size());
  for (size_t i = 0; i < table.radius_mm.size(); ++i)
    rows.col(i) << table.radius_mm[i], table.sag_mm[i], table.slope[i];
  return RowsArrayOf<3>(std::move(rows));
}

// ---------------------------------------------------------------- scenes and rendering

// A rendered view with the scene it points into (its view and targets live there).
struct PyRenderedView {
  std::shared_ptr<const Scene> scene;
  RenderedView rendered;
};

// One target's ground truth in a rendered view, as arrays (the <view>.json's corners).
struct TruthArrays {
  std::string name, spec_path, type;
  py::array_t<double> camera_from_target, target_mm, camera_mm, pixels;
  py::array_t<int> ids;
  py::array_t<std::uint8_t> status;
  py::array_t<bool> visible;
};

TruthArrays TruthOf(const TargetTruth& truth) {
  const PlacedTarget& placed = *truth.placement;
  const std::vector<CornerTruth>& corners = truth.corners;
  const size_t n = corners.size();
  Eigen::Matrix3Xd target_mm(3, n), camera_mm(3, n);
  Eigen::Matrix2Xd pixels(2, n);
  std::vector<int> ids(n);
  std::vector<std::uint8_t> status(n);
  py::array_t<bool> visible(static_cast<py::ssize_t>(n));
  for (size_t i = 0; i < n; ++i) {
    const CornerTruth& c = corners[i];
    ids[i] = c.id;
    target_mm.col(i) = c.point_in_target_mm;
    camera_mm.col(i) = c.point_in_camera_mm;
    // As the ground-truth file: a pixel only where the corner images (status ok).
    pixels.col(i) = c.status == ProjectionStatus::kOk ? c.pixel : Eigen::Vector2d::Constant(NAN);
    status[i] = static_cast<std::uint8_t>(c.status);
    visible.mutable_at(i) = c.visible;
  }
  return {placed.name,
          placed.spec_path,
          placed.target->type() == CalibrationTarget::Type::kAprilGrid ? "aprilgrid" : "checkerboard",
          PoseArray(placed.camera_from_target_rotation, placed.camera_from_target_translation_mm),
          RowsArrayOf<3>(std::move(target_mm)),
          RowsArrayOf<3>(std::move(camera_mm)),
          RowsArrayOf<2>(std::move(pixels)),
          VectorArray(std::move(ids)),
          VectorArray(std::move(status)),
          std::move(visible)};
}

// pybind11 passes None as an empty holder.
const Scene& SceneOf(const std::shared_ptr<Scene>& scene) {
  if (!scene) throw py::type_error("scene: expected an omnical.Scene, got None");
  return *scene;
}

py::list Render(const std::shared_ptr<Scene>& scene, int threads, py::object progress) {
  const Scene& given = SceneOf(scene);
  RenderOptions options;
  // 0: every core, as the CLI's default.
  options.threads = threads == 0 ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency())) : threads;
  options.progress = ForwardProgress(std::move(progress));
  std::vector<RenderedView> views = RunReleased([&] { return RenderScene(given, options); });
  py::list out;
  for (RenderedView& view : views) out.append(PyRenderedView{scene, std::move(view)});
  return out;
}

void SaveRendered(const std::shared_ptr<Scene>& scene, const std::vector<const PyRenderedView*>& views,
                  const py::object& out_dir, const py::object& scene_path) {
  SceneOf(scene);
  std::vector<RenderedView> rendered;
  for (const PyRenderedView* view : views) {
    if (!view || view->scene != scene) throw InputError("views: a view was not rendered from this scene");
    rendered.push_back(view->rendered);
  }
  const std::string dir = PathOf(out_dir);
  const std::string index_scene = scene_path.is_none() ? scene->path : PathOf(scene_path);
  GilReleased release;
  WriteRenderedScene(*scene, index_scene, rendered, dir);
}

void BindScene(py::module_& m) {
  py::class_<PlacedTarget>(m, "SceneTarget", "A target placed in a scene view (board frame: calib/target.h).")
      .def_readonly("name", &PlacedTarget::name, "The target's name in the scene's targets map.")
      .def_readonly("spec_path", &PlacedTarget::spec_path, "Its Kalibr-style spec file.")
      .def_property_readonly(
          "camera_from_target",
          [](const PlacedTarget& t) {
            return PoseArray(t.camera_from_target_rotation, t.camera_from_target_translation_mm);
          },
          "4x4 pose: point_in_camera_mm = (camera_from_target @ [point_in_target_mm, 1])[:3].")
      .def_property_readonly(
          "corner_ids",
          [](const PlacedTarget& t) {
            std::vector<int> ids;
            for (const TargetCorner& c : t.target->corners()) ids.push_back(c.id);
            return VectorArray(std::move(ids));
          },
          "(N,) int32: the board's corner ids (aprilgrid 4 tag + k, checkerboard row * cols + col).")
      .def_property_readonly(
          "corner_points_mm",
          [](const PlacedTarget& t) {
            Eigen::Matrix3Xd points(3, t.target->corners().size());
            for (size_t i = 0; i < t.target->corners().size(); ++i)
              points.col(i) = t.target->corners()[i].point_in_target;
            return RowsArrayOf<3>(std::move(points));
          },
          "(N, 3) float64: the corners in the board frame (mm, z = 0), in corner_ids' order.");
  py::class_<SceneView>(m, "SceneView", "One view of a scene: its name and the targets placed in it.")
      .def_readonly("name", &SceneView::name, "The view's name (its files are <name>.png and <name>.json).")
      .def_readonly("targets", &SceneView::targets, "The targets placed in this view (list of SceneTarget).");

  py::class_<Scene, std::shared_ptr<Scene>>(
      m, "Scene", R"(A synthetic scene for render: a sensor, planar targets placed around it per
view, an environment and the image formation settings (docs/file-formats.md "Scene file").)")
      .def_static(
          "load", [](const py::object& path) { return std::make_shared<Scene>(LoadSceneYaml(PathOf(path))); }, "path"_a,
          "Reads a scene file (YAML), its sensor and target specs. Raises InputError 'scene.yaml: field: problem'.")
      .def_readonly("path", &Scene::path, "The scene file it was loaded from.")
      .def_property_readonly(
          "sensor", [](const Scene& s) { return *s.sensor; }, "The scene's Sensor (a copy).")
      .def_readonly("views", &Scene::views, "The views (list of SceneView), random_views included, in render order.")
      .def_property_readonly(
          "view_names",
          [](const Scene& s) {
            std::vector<std::string> names;
            for (const SceneView& v : s.views) names.push_back(v.name);
            return names;
          },
          "The views' names, in render order.")
      .def_property_readonly(
          "formation",
          [](const Scene& s) {
            const ImageFormation& f = s.formation;
            return py::dict("samples_per_pixel"_a = f.samples_per_pixel, "noise_sigma"_a = f.noise_sigma,
                            "blur_sigma_px"_a = f.blur_sigma_px, "vignetting"_a = f.vignetting, "seed"_a = f.seed);
          },
          "The scene's render section: samples_per_pixel, noise_sigma, blur_sigma_px, vignetting, seed.")
      .def(
          "__len__", [](const Scene& s) { return s.views.size(); }, "The number of views.")
      .def("__repr__", [](const Scene& s) {
        return "<omnical.Scene " + s.path + ": " + std::to_string(s.views.size()) + " views, " +
               std::to_string(s.sensor->image_width_px()) + "x" + std::to_string(s.sensor->image_height_px()) + " px>";
      });

  py::class_<TruthArrays>(m, "TargetTruth", R"(One target's ground truth in a rendered view (the <view>.json's "targets"
entry): every corner's exact pixel through the exact sensor model.)")
      .def_readonly("name", &TruthArrays::name, "The target's name in the scene.")
      .def_readonly("spec_path", &TruthArrays::spec_path, "Its spec file (as the scene names it).")
      .def_readonly("type", &TruthArrays::type, "aprilgrid or checkerboard.")
      .def_readonly("camera_from_target", &TruthArrays::camera_from_target, "4x4 float64 pose (mm).")
      .def_readonly("ids", &TruthArrays::ids, "(N,) int32 corner ids.")
      .def_readonly("target_mm", &TruthArrays::target_mm, "(N, 3) float64: corners in the board frame (mm).")
      .def_readonly("camera_mm", &TruthArrays::camera_mm, "(N, 3) float64: corners in the camera frame (mm).")
      .def_readonly("pixels", &TruthArrays::pixels, "(N, 2) float64: exact pixels; NaN where status is not OK.")
      .def_readonly("status", &TruthArrays::status, "(N,) uint8 ProjectionStatus codes.")
      .def_readonly("visible", &TruthArrays::visible,
                    "(N,) bool: imaged, seen from the printed side and not hidden by another target.");

  py::class_<PyRenderedView>(m, "RenderedView", "A rendered view: its image and the ground truth of every corner.")
      .def_property_readonly("name", [](const PyRenderedView& v) { return v.rendered.view->name; }, "The view's name.")
      .def_property_readonly(
          "image",
          [](const PyRenderedView& v) {
            py::array image = ArrayOf(v.rendered.image);
            image.attr("flags").attr("writeable") = false;  // save_rendered writes this buffer
            return image;
          },
          "(H, W) uint8 grey image (read-only, no copy: .copy() to edit).")
      .def_property_readonly(
          "targets",
          [](const PyRenderedView& v) {
            std::vector<TruthArrays> targets;
            for (const TargetTruth& t : v.rendered.truth) targets.push_back(TruthOf(t));
            return targets;
          },
          "Ground truth per placed target (list of TargetTruth).");

  m.def("render", &Render, "scene"_a, py::kw_only(), "threads"_a = 0, "progress"_a = py::none(),
        R"(Ray-traces every view of the scene through the exact sensor model (as `omnical render`).

threads: worker threads, 0 = every core (the CLI's default). progress(stage, done, total)
hears 'render <view> (k/N)' with image rows; return False to cancel (omnical.Cancelled).
Deterministic: the same images for any number of threads. Returns a list of RenderedView.)");
  m.def("save_rendered", &SaveRendered, "scene"_a, "views"_a, "out_dir"_a, py::kw_only(), "scene_path"_a = py::none(),
        R"(Writes what `omnical render` writes: out_dir/<view>.png, <view>.json (ground truth),
sensor.yaml and scene.json (its index naming scene_path, default scene.path, relative to
out_dir). The views must come from render(scene).)");
}

// ---------------------------------------------------------------- design ode

DesignOdeResult DesignOde(const py::object& spec_path, const std::optional<std::string>& law,
                          const std::array<std::optional<double>, 9>& fields,
                          const py::object& law_table, int samples, int image_size_px, py::object progress) {
  DesignOdeOptions options;
  OdeDesignSpec& spec = options.spec;
  // The fields the CLI's flags set, in design_ode's order; None: not given.
  double* const targets[] = {&spec.focal_length_mm, &spec.distance_mm, &spec.start_height_mm, &spec.rim_limit_mm,
                             &spec.rho0_mm,         &spec.rho1_mm,     &spec.law.gain,         &spec.law.offset_mm,
                             &spec.law.growth_rate};
  bool any_field = law || !law_table.is_none();
  for (size_t i = 0; i < fields.size(); ++i)
    if (fields[i]) *targets[i] = *fields[i], any_field = true;
  if (!spec_path.is_none()) {
    if (any_field) throw InputError("spec: give a design spec file or law= and the design's fields, not both");
    spec = LoadOdeDesignSpec(PathOf(spec_path));
  } else {
    if (!law)
      throw InputError("spec: give a design spec file, or law= (linear, logpolar or table) and the design's fields");
    if (*law != "linear" && *law != "logpolar" && *law != "table")
      throw InputError("law: must be linear, logpolar or table, not '" + *law + "'");
    spec.law.kind = *law == "linear"     ? ImagingLaw::Kind::kLinear
                    : *law == "logpolar" ? ImagingLaw::Kind::kLogPolar
                                         : ImagingLaw::Kind::kTable;
    if (spec.law.kind == ImagingLaw::Kind::kLogPolar) spec.law.rho0_mm = spec.rho0_mm;
    if (spec.law.kind == ImagingLaw::Kind::kTable) {
      if (law_table.is_none()) throw InputError("law 'table' needs law_table=FILE (rows rho_mm, h_mm)");
      LoadLawTable(PathOf(law_table), &spec.law);
    }
  }
  options.samples = samples;
  options.image_size_px = image_size_px;
  options.progress = ForwardProgress(std::move(progress));
  return RunReleased([&] { return DesignMirrorOde(options); });
}

void SaveOde(const DesignOdeResult& r, const py::object& out_dir) {
  const std::filesystem::path dir(PathOf(out_dir));
  const std::string table_file = DesignOdeOptions().table_file;  // the name the sensor's mirror.table gives
  GilReleased release;
  CreateOutputDirectory(dir.string());
  WriteProfileTable(r.profile, "design ode", (dir / table_file).string());
  WriteOdeDesignSensorYaml(r, table_file, (dir / "sensor.yaml").string());
  WriteLawRatioCsv(r, (dir / "law_ratio.csv").string());
  WriteOdeDesignFigures(r, dir.string());
  WriteOdeDesignJson(r, (dir / "design.json").string());
}

void BindDesignOde(py::module_& m) {
  py::class_<DesignOdeResult> result(m, "DesignOdeResult",
                                     R"(A mirror from Gächter's reflection ODE (model/design/design_ode_job.h):
the profile, the designed sensor, its field of view and the law checked by tracing rays
through that sensor on cylinders at 0.5, 0.75, 1, 1.5 and 2 x the reference distance.)");
  result
      .def_readonly("sensor", &DesignOdeResult::sensor,
                    "The designed Sensor (tabulated mirror, pinhole lens; its mirror.table is profile.csv).")
      .def_property_readonly(
          "profile_table", [](const DesignOdeResult& r) { return ProfileArray(r.profile); },
          "(N, 3) float64 as profile.csv: radius_mm, sag_mm (from the vertex), slope dz/dx.")
      .def_property_readonly(
          "fov_deg", [](const DesignOdeResult& r) { return r.design.phi1_deg - r.design.phi0_deg; },
          "Vertical field of view phi1 - phi0 (deg).")
      .def_property_readonly(
          "ended_at_rim", [](const DesignOdeResult& r) { return r.design.ended_at_rim; },
          "True when the field ends at the rim limit t1 (inside rho1).")
      .def_property_readonly(
          "ode_steps", [](const DesignOdeResult& r) { return r.design.ode_steps; },
          "Steps the adaptive ODE solver took.")
      .def_readonly("vertex_height_mm", &DesignOdeResult::vertex_height_mm, "F0: image plane to mirror vertex (mm).")
      .def_readonly("m_mm", &DesignOdeResult::m_mm, "Lens to mirror vertex, F0 - f (mm).")
      .def_readonly("pixel_pitch_mm", &DesignOdeResult::pixel_pitch_mm, "The designed sensor's pixel pitch (mm).")
      .def_readonly("max_law_error_rel", &DesignOdeResult::max_law_error_rel,
                    "max |ratio - 1| at the reference distance (inf where a ray missed).")
      .def_property_readonly(
          "law_ratio_distance_mm",
          [](const DesignOdeResult& r) {
            return Column(r.law_ratio.size(), [&](size_t i) { return r.law_ratio[i].distance_mm; });
          },
          "(K,) the cylinder radii the law was traced at (mm); index 2 is the reference distance.")
      .def_property_readonly(
          "law_ratio_rho_mm",
          [](const DesignOdeResult& r) { return VectorArray(std::vector<double>(r.reference_curve().rho_mm)); },
          "(M,) the midpoints of the rho intervals (mm).")
      .def_property_readonly(
          "law_ratio",
          [](const DesignOdeResult& r) {
            py::array_t<double> ratio({static_cast<py::ssize_t>(r.law_ratio.size()),
                                       static_cast<py::ssize_t>(r.reference_curve().ratio.size())});
            auto out = ratio.mutable_unchecked<2>();
            for (size_t k = 0; k < r.law_ratio.size(); ++k)
              for (size_t i = 0; i < r.law_ratio[k].ratio.size(); ++i) out(k, i) = r.law_ratio[k].ratio[i];
            return ratio;
          },
          "(K, M): traced increment of h over the law's, divided by distance / d (1 = the law, scaled).")
      .def("save", &SaveOde, "out_dir"_a,
           R"(Writes what `omnical design ode` writes: profile.csv, sensor.yaml, law_ratio.csv,
design.json and the figures (law_ratio.png, profile.png, profile_drawing.svg/.png).)");
  const std::tuple<const char*, double OdeDesign::*, const char*> design_numbers[] = {
      {"phi0_deg", &OdeDesign::phi0_deg, "Elevation (from -z) seen at rho0 (deg)."},
      {"phi1_deg", &OdeDesign::phi1_deg, "Elevation seen at the field's end (deg)."},
      {"t_start_mm", &OdeDesign::t_start_mm, "Mirror radius imaged at rho0 (mm)."},
      {"t_end_mm", &OdeDesign::t_end_mm, "Mirror radius at the field's end: the designed mirror's rim (mm)."},
      {"rho_end_mm", &OdeDesign::rho_end_mm,
       "Image radius of the field's end: rho1, or the rim's image before it (mm)."}};
  for (const auto& [name, field, doc] : design_numbers)
    result.def_property_readonly(name, [field = field](const DesignOdeResult& r) { return r.design.*field; }, doc);

  m.def(
      "design_ode",
      [](const py::object& spec, const std::optional<std::string>& law, std::optional<double> focal_length_mm,
         std::optional<double> distance_mm, std::optional<double> start_height_mm, std::optional<double> rim_limit_mm,
         std::optional<double> rho0_mm, std::optional<double> rho1_mm, std::optional<double> gain,
         std::optional<double> offset_mm, std::optional<double> growth_rate, const py::object& law_table, int samples,
         int image_size_px, py::object progress) {
        return DesignOde(spec, law,
                         {focal_length_mm, distance_mm, start_height_mm, rim_limit_mm, rho0_mm, rho1_mm, gain,
                          offset_mm, growth_rate},
                         law_table, samples, image_size_px, std::move(progress));
      },
      "spec"_a = py::none(), py::kw_only(), "law"_a = py::none(), "focal_length_mm"_a = py::none(),
      "distance_mm"_a = py::none(), "start_height_mm"_a = py::none(), "rim_limit_mm"_a = py::none(),
      "rho0_mm"_a = py::none(), "rho1_mm"_a = py::none(), "gain"_a = py::none(), "offset_mm"_a = py::none(),
      "growth_rate"_a = py::none(), "law_table"_a = py::none(), "samples"_a = 20001, "image_size_px"_a = 1000,
      "progress"_a = py::none(),
      R"(A mirror from Gächter's reflection ODE for an imaging law (as `omnical design ode`).

Either spec: a design spec file (YAML, datasets-synthetic/designs), or law= 'linear',
'logpolar' or 'table' with the design's fields (mm): focal_length_mm (f), distance_mm (d),
start_height_mm (F0), rim_limit_mm (t1), rho0_mm, rho1_mm (the imager's used radii),
gain, offset_mm, growth_rate (logpolar) and law_table (table: CSV rows rho_mm, h_mm).
samples: profile samples; image_size_px: the designed sensor's square image.
progress(stage, done, total) hears "ode" and "trace law". Returns a DesignOdeResult.)");
}

// ---------------------------------------------------------------- design fit

void BindDesignFit(py::module_& m) {
  py::class_<CharacteristicReport>(m, "CharacteristicReport", R"(How closely an axial sensor follows each image law,
measured through its own model (model/design/mirror_design_fit.h).)")
      .def_property_readonly(
          "samples",
          [](const CharacteristicReport& r) {
            const auto& s = r.samples;
            return py::dict("x_mm"_a = Column(s.size(), [&](size_t i) { return s[i].x_mm; }),
                            "omega_deg"_a = Column(s.size(), [&](size_t i) { return s[i].omega_deg; }),
                            "h_px"_a = Column(s.size(), [&](size_t i) { return s[i].h_px; }),
                            "viewpoint_z_mm"_a = Column(s.size(), [&](size_t i) { return s[i].viewpoint_z_mm; }));
          },
          "Dict of (N,) arrays from the vertex to the rim: x_mm, omega_deg, h_px, viewpoint_z_mm (Eq. 6).")
      .def_readonly("rim_h_px", &CharacteristicReport::rim_h_px, "Image radius of the rim (px).")
      .def_readonly("rim_omega_deg", &CharacteristicReport::rim_omega_deg, "Omega at the rim (deg).")
      .def_readonly("rim_theta_deg", &CharacteristicReport::rim_theta_deg, "Theta at the rim (deg).")
      .def_readonly("equidistant_max_px", &CharacteristicReport::equidistant_max_px,
                    "max |h - h_law| (px), equidistant.")
      .def_readonly("constant_aspect_max_px", &CharacteristicReport::constant_aspect_max_px,
                    "max |h - h_law| (px), constant aspect ratio.")
      .def_readonly("equal_area_max_px", &CharacteristicReport::equal_area_max_px, "max |h - h_law| (px), equal area.")
      .def_readonly("viewpoint_spread_mm", &CharacteristicReport::viewpoint_spread_mm,
                    "max - min z_v over the mirror (mm).");

  py::class_<DesignFitResult>(m, "DesignFitResult", R"(Ohte & Tsuzuki's design by parameters (Table 1) solved with Ceres
(model/design/design_fit_job.h): the normalised parameters, the sensor in mm and the laws it achieves.)")
      .def_readonly("sensor", &DesignFitResult::sensor, "The designed axial Sensor (mm).")
      .def_property_readonly(
          "profile", [](const DesignFitResult& r) { return r.spec.profile; },
          "The profile family: one of omnical.DESIGN_PROFILES.")
      .def_property_readonly(
          "characteristic", [](const DesignFitResult& r) { return CharacteristicName(r.spec.characteristic); },
          "The characteristic fitted: none, equidistant, svp, aspect or area.")
      .def_property_readonly(
          "law", [](const DesignFitResult& r) { return CharacteristicName(r.law); },
          "The law the curves are measured against.")
      .def_property_readonly(
          "parameters",
          [](const DesignFitResult& r) {
            py::dict parameters;
            for (const auto& [name, value] : NormalisedParameters(r.design)) parameters[py::str(name)] = value;
            return parameters;
          },
          "Normalised parameters (mirror radius 1) with Table 1's names: sphere A, m; hyperboloid A, B, m; "
          "polynomial c1..cn, m.")
      .def_readonly("rim_radius_mm", &DesignFitResult::rim_radius_mm, "The rim radius M the design is scaled by (mm).")
      .def_property_readonly(
          "profile_table", [](const DesignFitResult& r) { return ProfileArray(r.profile); },
          "(N, 3) float64 as profile.csv: radius_mm, sag_mm, slope.")
      .def_readonly("achieved", &DesignFitResult::achieved,
                    "The laws the designed sensor achieves (CharacteristicReport).")
      .def_readonly("compared", &DesignFitResult::compared, "Those of the compared sensor, or None.")
      .def_property_readonly(
          "free_parameters", [](const DesignFitResult& r) { return r.design.free_params; },
          "Parameters left free after the two rim targets.")
      .def_property_readonly(
          "iterations", [](const DesignFitResult& r) { return r.design.iterations; }, "Ceres iterations.")
      .def_property_readonly(
          "final_cost", [](const DesignFitResult& r) { return r.design.final_cost; },
          "Ceres' final cost (1/2 sum of squared normalised residuals).")
      .def_property_readonly(
          "solver_report", [](const DesignFitResult& r) { return r.design.solver_report; },
          "Ceres' brief report ('closed form' for a sphere).")
      .def(
          "save",
          [](const DesignFitResult& r, const py::object& out_dir) {
            const std::filesystem::path dir(PathOf(out_dir));
            GilReleased release;
            CreateOutputDirectory(dir.string());
            SaveSensorYaml(r.sensor, (dir / "sensor.yaml").string());
            WriteProfileTable(r.profile, "design fit", (dir / "profile.csv").string());
            WriteFitCharacteristicCsv(r, (dir / "characteristic.csv").string());
            WriteFitDesignFigures(r, dir.string());
            WriteFitDesignJson(r, "sensor.yaml", (dir / "design.json").string());
          },
          "out_dir"_a,
          R"(Writes what `omnical design fit` writes: sensor.yaml, profile.csv, characteristic.csv,
design.json and the figures (characteristic.png, profile_drawing.svg/.png).)");

  m.def(
      "design_fit",
      [](const std::string& profile, int terms, double rim_omega_deg, double rim_theta_deg,
         const py::object& characteristic, double rim_radius_mm, int image_size_px, const py::object& compare,
         int samples, int characteristic_samples, int profile_samples, py::object progress) {
        DesignFitOptions o;
        const std::vector<std::string> profiles = DesignProfileNames();
        if (std::find(profiles.begin(), profiles.end(), profile) == profiles.end())
          throw InputError("profile: must be " + JoinChoices(profiles) + ", not '" + profile + "'");
        o.spec.profile = profile;
        o.spec.terms = terms;
        o.spec.rim_omega_deg = rim_omega_deg;
        o.spec.rim_theta_deg = rim_theta_deg;
        o.spec.samples = samples;
        o.spec.characteristic = DefaultCharacteristic(profile, terms);
        if (!characteristic.is_none()) {
          const std::string name = py::str(characteristic);
          bool known = false;
          for (ImageCharacteristic c : {ImageCharacteristic::kNone, ImageCharacteristic::kEquidistant,
                                        ImageCharacteristic::kSingleViewpoint, ImageCharacteristic::kConstantAspect,
                                        ImageCharacteristic::kEqualArea})
            if (name == CharacteristicName(c)) o.spec.characteristic = c, known = true;
          if (!known)
            throw InputError("characteristic: must be none, equidistant, svp, aspect or area, not '" + name + "'");
        }
        o.rim_radius_mm = rim_radius_mm;
        o.image_size_px = image_size_px;
        o.characteristic_samples = characteristic_samples;
        o.profile_samples = profile_samples;
        if (py::isinstance<Sensor>(compare)) {
          o.compare = compare.cast<Sensor>();
          o.compare_source = "compare";
        } else if (!compare.is_none()) {  // a sensor file, named in messages as the CLI does
          o.compare_source = PathOf(compare);
          try {
            o.compare = LoadSensorYaml(o.compare_source);
          } catch (const InputError& e) {
            const std::string what = e.what();
            throw InputError(what.rfind(o.compare_source, 0) == 0 ? what : o.compare_source + ": " + what);
          }
        }
        o.progress = ForwardProgress(std::move(progress));
        return RunReleased([&] { return DesignMirrorFit(o); });
      },
      py::kw_only(), "profile"_a, "terms"_a = 3, "rim_omega_deg"_a = 135.0, "rim_theta_deg"_a = 12.0,
      "characteristic"_a = py::none(), "rim_radius_mm"_a = 43.9, "image_size_px"_a = 1000, "compare"_a = py::none(),
      "samples"_a = 200, "characteristic_samples"_a = 1000, "profile_samples"_a = 2000, "progress"_a = py::none(),
      R"(Ohte & Tsuzuki's design by parameters (Table 1), solved with Ceres (as `omnical design fit`).

profile: one of omnical.DESIGN_PROFILES; terms: how many terms the family's list has
(polynomial c1 x^2 .. cn x^2n; see docs/file-formats.md for the others);
rim_omega_deg / rim_theta_deg: the rim ray's Omega and the lens's Theta at the rim;
characteristic: equidistant, svp, aspect, area or none (default: svp for a hyperboloid,
equidistant for a family with freedom left after the rim targets, else none); rim_radius_mm scales the normalised design; image_size_px:
the rim images at half of it; compare: another axial sensor (Sensor or file) measured the
same way; samples: characteristic residuals of the fit; characteristic_samples: mirror
radii the laws are measured at; profile_samples: intervals of the profile table.
progress hears "measure compared", "fit", "measure". Returns a DesignFitResult.)");
}

// ---------------------------------------------------------------- characterize

struct PyCharacterization {
  CharacterizeResult result;
  std::string sensor_file;  // what summary.json names the analysed sensor
};

// The columns of characteristics.csv (model/design/design_files.cc): same names, order and units.
py::dict CharacteristicCurves(const CharacterizeResult& r) {
  static const char* const names[] = {
      "x_mm", "z_mm", "omega_deg", "theta_deg", "beta_deg", "gamma_deg", "viewpoint_z_mm", "h_px",
      "dh_domega_px_per_deg", "delta_w_px", "delta_s_px2", "aspect_ratio", "tangential_curvature_per_mm",
      "sagittal_curvature_per_mm", "t_inf_x_mm", "t_inf_z_mm", "s_inf_x_mm", "s_inf_z_mm", "t_near_x_mm",
      "t_near_z_mm", "s_near_x_mm", "s_near_z_mm", "L_t_inf_mm", "L_s_inf_mm", "blur_t_px", "blur_s_px", "blur_t_deg",
      "blur_s_deg", "blur_area_deg2", "caustic_x_mm", "caustic_z_mm"};
  constexpr int kColumns = static_cast<int>(std::size(names));
  Eigen::MatrixXd table(r.field.size(), kColumns);
  for (size_t i = 0; i < r.field.size(); ++i) {
    const FieldSample& f = r.field[i];
    const BlurSpot& b = r.blur[i];
    const AxialRayQuantities& q = f.ray;
    table.row(i) << q.x_mm, q.z_mm, q.omega_rad * kDeg, q.theta_rad * kDeg, q.beta_rad * kDeg, q.gamma_rad * kDeg,
        q.viewpoint_z_mm, f.h_px, f.delta_h_px, f.delta_w_px, f.delta_s_px2, f.aspect_ratio,
        f.tangential_curvature_per_mm, f.sagittal_curvature_per_mm, f.tangential_far.x_mm, f.tangential_far.z_mm,
        f.sagittal_far.x_mm, f.sagittal_far.z_mm, f.tangential_near.x_mm, f.tangential_near.z_mm,
        f.sagittal_near.x_mm, f.sagittal_near.z_mm, f.tangential_far.lens_distance_mm,
        f.sagittal_far.lens_distance_mm, b.tangential_px, b.sagittal_px, b.tangential_deg, b.sagittal_deg, b.area_deg2,
        f.caustic_x_mm, f.caustic_z_mm;
  }
  py::dict curves;
  for (int k = 0; k < kColumns; ++k)
    curves[names[k]] = VectorArray(std::vector<double>(table.col(k).data(), table.col(k).data() + table.rows()));
  return curves;
}

void BindCharacterize(py::module_& m) {
  py::class_<PyCharacterization> result(m, "CharacterizeResult",
                                        R"(The seed paper's evaluation of a sensor (Ohte & Tsuzuki Secs. 2-3;
model/design/characterize.h): image-forming characteristics, viewpoints, virtual images,
blur and depth of field over the mirror.)");
  result
      .def_property_readonly(
          "curves", [](const PyCharacterization& c) { return CharacteristicCurves(c.result); },
          "Dict of (samples,) float64 arrays, the columns of characteristics.csv (same names).")
      .def_property_readonly(
          "azimuth_curves",
          [](const PyCharacterization& c) {
            py::list curves;
            for (const auto& curve : c.result.azimuth_curves) {
              Eigen::Matrix3Xd rows(3, curve.size());
              for (size_t i = 0; i < curve.size(); ++i)
                rows.col(i) << curve[i].x_mm, curve[i].omega_rad * kDeg, curve[i].h_px;
              curves.append(RowsArrayOf<3>(std::move(rows)));
            }
            return curves;
          },
          "Tilted or decentred sensor: (N, 3) x_mm, omega_deg, h_px along azimuths 0, 90, 180, 270 deg; else [].")
      .def_property_readonly(
          "profile", [](const PyCharacterization& c) { return c.result.profile_name; }, "Mirror profile.")
      .def_property_readonly(
          "lens", [](const PyCharacterization& c) { return c.result.lens_name; }, "Lens model.")
      .def_property_readonly(
          "axial", [](const PyCharacterization& c) { return c.result.axial; },
          "False: analysed as the aligned counterpart (azimuth_curves exact).")
      .def_property_readonly(
          "samples", [](const PyCharacterization& c) { return c.result.samples; }, "Mirror radii analysed.")
      .def_property_readonly(
          "lens_focal_mm", [](const PyCharacterization& c) { return c.result.lens.lens_focal_mm; },
          "Lens focal length of the blur analysis (mm).")
      .def_property_readonly(
          "f_number", [](const PyCharacterization& c) { return c.result.lens.f_number; }, "f-number.")
      .def_property_readonly(
          "focus_searched", [](const PyCharacterization& c) { return c.result.focus_searched; },
          "True when L0 was searched (focus_mm not given).")
      .def_property_readonly(
          "viewpoint_spread_mm", [](const PyCharacterization& c) { return c.result.viewpoint_spread_mm(); },
          "z_v range (mm): 0 for a single viewpoint.")
      .def_property_readonly(
          "rim_omega_deg", [](const PyCharacterization& c) { return c.result.rim_omega_deg(); },
          "Omega at the rim (deg).")
      .def_property_readonly(
          "rim_theta_deg", [](const PyCharacterization& c) { return c.result.rim_theta_deg(); },
          "Theta at the rim (deg).")
      .def(
          "save",
          [](const PyCharacterization& c, const py::object& out_dir) {
            const std::filesystem::path dir(PathOf(out_dir));
            GilReleased release;
            CreateOutputDirectory(dir.string());
            WriteCharacteristicsCsv(c.result, (dir / "characteristics.csv").string());
            WriteCharacterizeSummaryJson(c.result, c.sensor_file, (dir / "summary.json").string());
            WriteCharacterizeFigures(c.result, dir.string());
          },
          "out_dir"_a,
          R"(Writes what `omnical characterize` writes: characteristics.csv, summary.json (naming the
sensor file characterize was given, or "sensor" for a Sensor object) and fig04..fig09 PNGs.)");
  const std::tuple<const char*, double CharacterizeResult::*, const char*> scalars[] = {
      {"rim_radius_mm", &CharacterizeResult::rim_radius_mm, "Rim radius (mm)."},
      {"m_mm", &CharacterizeResult::m_mm, "Lens to mirror vertex (mm)."},
      {"pixel_um", &CharacterizeResult::pixel_um, "Pixel size (um)."},
      {"near_distance_mm", &CharacterizeResult::near_distance_mm, "Near object distance of the virtual images (mm)."},
      {"focus_mm", &CharacterizeResult::focus_mm, "In-focus distance L0 (mm)."},
      {"depth_of_field_mm", &CharacterizeResult::depth_of_field_mm, "Depth of field (mm; inf beyond hyperfocal)."},
      {"mean_blur_area_deg2", &CharacterizeResult::mean_blur_area_deg2, "Weighted mean blur area at L0 (deg^2)."},
      {"viewpoint_min_mm", &CharacterizeResult::viewpoint_min_mm, "Lowest viewpoint z_v (Eq. 6, mm)."},
      {"viewpoint_max_mm", &CharacterizeResult::viewpoint_max_mm, "Highest viewpoint z_v (mm)."},
      {"caustic_radial_mm", &CharacterizeResult::caustic_radial_mm, "Caustic's radial extent (mm)."},
      {"caustic_axial_mm", &CharacterizeResult::caustic_axial_mm, "Caustic's axial extent (mm)."},
      {"max_astigmatism_mm", &CharacterizeResult::max_astigmatism_mm,
       "max |L_t - L_s| of the far virtual images (mm)."},
      {"worst_blur_px", &CharacterizeResult::worst_blur_px, "Largest blur spot (px)."},
      {"dh_domega_min", &CharacterizeResult::dh_domega_min, "Smallest dh/dOmega (px/deg)."},
      {"dh_domega_max", &CharacterizeResult::dh_domega_max, "Largest dh/dOmega (px/deg)."},
      {"mean_solid_angle_per_pixel_deg2", &CharacterizeResult::mean_solid_angle_per_pixel_deg2,
       "Mean solid angle per pixel over the field (deg^2)."}};
  for (const auto& [name, field, doc] : scalars)
    result.def_property_readonly(name, [field = field](const PyCharacterization& c) { return c.result.*field; }, doc);

  m.def(
      "characterize",
      [](const py::object& sensor_or_path, const std::optional<double>& lens_focal_mm,
         const std::optional<double>& focus_mm, double f_number, double pixel_um, double near_n, int samples,
         py::object progress) {
        PyCharacterization out;
        const bool is_sensor = py::isinstance<Sensor>(sensor_or_path);
        out.sensor_file = is_sensor ? "sensor" : PathOf(sensor_or_path);
        const Sensor sensor = is_sensor ? sensor_or_path.cast<Sensor>() : LoadSensorYaml(out.sensor_file);
        CharacterizeOptions o;
        o.lens_focal_mm = lens_focal_mm;
        o.focus_mm = focus_mm;
        o.f_number = f_number;
        o.pixel_um = pixel_um;
        o.near_n = near_n;
        o.samples = samples;
        o.progress = ForwardProgress(std::move(progress));
        out.result = RunReleased([&] {
          try {
            return Characterize(sensor, o);
          } catch (const InputError& e) {  // "sensor: ..." is about the sensor file, as the CLI names it
            const std::string what = e.what();
            if (is_sensor || what.rfind("sensor: ", 0) != 0) throw;
            throw InputError(InputMessage(out.sensor_file, "", what.substr(8)));
          }
        });
        return out;
      },
      "sensor"_a, py::kw_only(), "lens_focal_mm"_a = py::none(), "focus_mm"_a = py::none(), "f_number"_a = 4.0,
      "pixel_um"_a = 5.2, "near_n"_a = 5.0, "samples"_a = 540, "progress"_a = py::none(),
      R"(The seed paper's evaluation of a sensor (as `omnical characterize`).

sensor: a Sensor or a sensor file. lens_focal_mm: the lens of the blur analysis (default:
the sensor's fx x pixel size); focus_mm: in-focus distance L0 (default: searched);
f_number; pixel_um: pixel size, the permissible circle of confusion; near_n: near object
distance of the virtual images in mirror radii; samples: mirror radii analysed.
progress hears "field", "focus", "azimuth curves". Returns a CharacterizeResult.)");
}

}  // namespace

void BindDesign(py::module_& m) {
  BindScene(m);
  BindDesignOde(m);
  BindDesignFit(m);
  BindCharacterize(m);
}

}  // namespace omnical::python
