// omnical remap: a remap table from the omni image to a virtual screen, exact for objects
// on the chosen surface (or at infinity), exported for OpenCV, ffmpeg and NumPy, with
// maps.json describing the view completely and how wrong the table is at other distances.
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "correction/map_export.h"
#include "correction/remap_error.h"
#include "model/atomic_write.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "calib/report/plot.h"
#include "tools/progress.h"
#include "tools/view_setup.h"

namespace omnical::cli {
namespace {

struct Options {
  std::string sensor_path, out_dir;
  std::vector<std::string> formats{"opencv"};
  ViewOptions view;
};

// The largest difference between table entries and fresh scalar projections of their
// object points, over a random sample of output pixels: what the file promises.
double ExactnessCheckPx(const Sensor& sensor, const RemapSettings& settings, const RemapTable& table, int samples) {
  std::mt19937 random(1);
  std::uniform_int_distribution<int> col(0, table.width - 1), row(0, table.height - 1);
  double worst = 0.0;
  for (int i = 0; i < samples; ++i) {
    const int u = col(random), v = row(random);
    const size_t k = static_cast<size_t>(v) * table.width + u;
    Eigen::Vector3d point;
    Eigen::Vector2d pixel;
    if (table.map_x[k] < 0.0f || !RemapObjectPoint(sensor, settings, u, v, &point)) continue;
    const ProjectionCache& cache = sensor.cache();
    if (sensor.Project(cache.camera_from_mirror_rotation * point + cache.camera_from_mirror_translation, &pixel) !=
        ProjectionStatus::kOk)
      return HUGE_VAL;  // the table has an entry the scalar path refuses
    worst = std::max(worst, (Eigen::Vector2d(table.map_x[k], table.map_y[k]) - pixel).norm());
  }
  return worst;
}

void Run(const Options& options, const Context& context) {
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  const std::set<std::string> formats(options.formats.begin(), options.formats.end());
  const ResolvedView resolved = ResolveView(sensor, options.view);
  const RemapSettings& settings = resolved.settings;
  const double rim = sensor.rim_radius_mm();

  RemapTable table;
  const auto start = std::chrono::steady_clock::now();
  {
    Progress progress("remap table", settings.screen.height_px, context.quiet);
    table = BuildRemapTable(sensor, settings, [&](long rows) { progress.Advance(rows); });
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double valid_fraction = double(table.valid_pixels) / (double(table.width) * table.height);
  if (table.valid_pixels == 0)
    throw InputError("--view: no output pixel sees the mirror: the view lies outside the mirror's field (elevation " +
                     std::to_string(settings.screen.elevation_bottom_deg) + " .. " +
                     std::to_string(settings.screen.elevation_top_deg) + " deg at most)");

  // How wrong the table is for objects elsewhere (seed Eq. 23, in output pixels).
  const int stride = std::max(1, std::max(table.width, table.height) / 96);
  nlohmann::json residual = nlohmann::json::array();
  std::vector<double> curve_n, curve_max, curve_rms;
  for (double n : {1.5, 2.0, 3.0, 5.0, 7.0, 10.0, 20.0, 40.0, 100.0, HUGE_VAL}) {
    const ObjectSurface object = ObjectAtDistance(settings.surface, n * rim);
    const RemapErrorStats stats = RemapErrorAt(sensor, settings, object, stride);
    residual.push_back({{"n", std::isfinite(n) ? nlohmann::json(n) : nlohmann::json("infinity")},
                        {"distance_mm", std::isfinite(n) ? nlohmann::json(n * rim) : nlohmann::json("infinity")},
                        {"max_px", stats.max_px},
                        {"rms_px", stats.rms_px},
                        {"samples", stats.samples}});
    if (std::isfinite(n)) curve_n.push_back(n), curve_max.push_back(stats.max_px), curve_rms.push_back(stats.rms_px);
  }
  const double exactness_px = ExactnessCheckPx(sensor, settings, table, 4000);

  CreateOutputDirectory(options.out_dir);
  const std::filesystem::path dir(options.out_dir);
  nlohmann::json files = nlohmann::json::object();
  if (formats.count("opencv")) {
    WriteOpenCvMaps(table, (dir / "maps.yml.gz").string(), (dir / "maps_fixed.yml.gz").string());
    files["opencv"] = {{"float", "maps.yml.gz"}, {"fixed_point", "maps_fixed.yml.gz"}};
  }
  std::string ffmpeg_command;
  if (formats.count("ffmpeg")) {
    WriteFfmpegMaps(table, (dir / "xmap.pgm").string(), (dir / "ymap.pgm").string());
    ffmpeg_command = "ffmpeg -i INPUT -i " + (dir / "xmap.pgm").string() + " -i " + (dir / "ymap.pgm").string() +
                     " -filter_complex \"[0:v][1:v][2:v]remap\" OUTPUT";
    files["ffmpeg"] = {{"xmap", "xmap.pgm"}, {"ymap", "ymap.pgm"}, {"command", ffmpeg_command}};
  }
  if (formats.count("npy")) {
    WriteNpyMaps(table, (dir / "map_x.npy").string(), (dir / "map_y.npy").string());
    files["npy"] = {{"map_x", "map_x.npy"}, {"map_y", "map_y.npy"}};
  }

  PlotPanel panel{"Error of this table for objects at other distances (n rim radii from V0)", "n (mirror rim radii)",
                  "error (output px)"};
  std::vector<double> log_n;
  for (double n : curve_n) log_n.push_back(std::log10(n));
  panel.x_label = "log10 n (object distance in mirror rim radii)";
  panel.series.push_back({"max", log_n, curve_max, SeriesColor(0)});
  panel.series.push_back({"rms", log_n, curve_rms, SeriesColor(1)});
  WritePng((dir / "remap_error.png").string(), RenderPanel(panel, 900, 520));

  std::stringstream sensor_yaml;
  sensor_yaml << std::ifstream(options.sensor_path).rdbuf();
  nlohmann::json j;
  j["view"] = ScreenJson(settings.screen);
  j["sensor"] = {{"file", options.sensor_path}, {"yaml", sensor_yaml.str()},
                 {"image_size_px", {sensor.image_width_px(), sensor.image_height_px()}}};
  j["surface"] = SurfaceJson(settings.surface, rim);
  j["v0_mm"] = settings.v0_mm;
  j["v0_searched"] = resolved.v0_searched;
  j["map_convention"] = "omni-image pixel to sample (centre of pixel (0, 0) at (0, 0)); -1 where the output pixel sees no mirror";
  j["files"] = files;
  j["valid_fraction"] = valid_fraction;
  j["used_axial_symmetry"] = table.used_axial_symmetry;
  j["method"] = table.used_axial_symmetry ? "axial symmetry" : table.interpolation_step_px > 0 ? "interpolated grid" : "per pixel";
  if (table.interpolation_step_px > 0)
    j["interpolation"] = {{"step_px", table.interpolation_step_px},
                          {"pixels_projected_one_by_one", table.exact_pixels},
                          {"worst_cell_check_px", table.worst_cell_check_px},
                          {"bound_px", 0.01}};
  j["generation_seconds"] = seconds;
  j["threads"] = settings.threads;
  j["exactness_check"] = {{"max_error_px", exactness_px},
                          {"meaning", "table entries vs fresh exact projections of their object points, 4000 random pixels"}};
  j["error_at_other_distances"] = residual;
  WriteOutput((dir / "maps.json").string(), [&](std::ostream& out) { out << j.dump(2) << '\n'; });

  if (!context.quiet) {
    char objects[96] = "at infinity";
    if (settings.surface.kind != ObjectSurface::Kind::kInfinity)
      std::snprintf(objects, sizeof objects, "on a %s at %.1f mm (n = %.3g)", SurfaceKindName(settings.surface.kind),
                    settings.surface.distance_mm, settings.surface.distance_mm / rim);
    std::printf("%s %dx%d, objects %s, V0 = %.3f mm: %.1f%% of pixels see the mirror, %.3f s%s -> %s\n",
                ScreenTypeName(settings.screen.type), table.width, table.height,
                objects,
                settings.v0_mm, 100.0 * valid_fraction, seconds,
                table.used_axial_symmetry ? " (axial symmetry)" : table.interpolation_step_px > 0 ? " (interpolated grid)" : "",
                options.out_dir.c_str());
    std::printf("  exact to %.2g px; error at other distances (max output px):", exactness_px);
    for (const auto& r : residual) std::printf(" n=%s %.3g", r["n"].dump().c_str(), r["max_px"].get<double>());
    std::printf("\n");
    if (!ffmpeg_command.empty()) std::printf("  ffmpeg: %s\n", ffmpeg_command.c_str());
  }
}

}  // namespace

Command RemapCommand() {
  return {"remap", "Remap tables to a virtual screen (panorama, lonlat, perspective, equiangular), exact at a known distance",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<Options>();
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            sub.add_option("--format", options->formats, "Formats: opencv, ffmpeg, npy (comma separated)")
                ->delimiter(',')
                ->check(CLI::IsMember({"opencv", "ffmpeg", "npy"}))
                ->capture_default_str();
            AddViewOptions(sub, &options->view, true);
            return [options, &context]() { Run(*options, context); };
          }};
}

}  // namespace omnical::cli
