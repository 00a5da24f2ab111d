// A panorama remap table exact for objects 7 mirror rim radii from the viewpoint V0 (the
// parallax of the non-central mirror corrected at that distance), built from C++, checked
// against direct projections of the objects its pixels look at, and applied to an image.
// Usage: remap_image SENSOR.yaml OMNI_IMAGE OUT.png
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <variant>

#include "correction/remap_job.h"
#include "correction/unwarp.h"
#include "model/input_error.h"
#include "model/io/sensor_yaml.h"

int main(int argc, char** argv) {
  if (argc != 4) return 2;
  try {
    const omnical::Sensor sensor = omnical::LoadSensorYaml(argv[1]);
    omnical::RemapOptions options;
    options.view.view = "panorama";
    options.view.size = "720x180";
    options.view.n = 7.0;  // objects on a sphere 7 rim radii around V0
    const omnical::RemapResult remap = omnical::BuildRemap(sensor, options);
    const omnical::RemapTable& table = remap.table;
    std::printf("V0 at z = %.3f mm; %.1f%% of the panorama sees the mirror\n", remap.settings.v0_mm,
                100.0 * remap.valid_fraction);

    // Independent check: an output pixel looks along the screen's direction from V0; the
    // object 7 rim radii away on that line, projected through the sensor, must land where
    // the table says (the tables promise 0.01 px).
    const double distance_mm = 7.0 * sensor.rim_radius_mm();
    double worst_px = 0.0;
    int checked = 0;
    for (int row = 5; row < table.height; row += 17)
      for (int col = 3; col < table.width; col += 29) {
        const size_t k = static_cast<size_t>(row) * table.width + col;
        Eigen::Vector3d direction;
        if (table.map_x[k] < 0.0f || !remap.settings.screen.Direction(col, row, &direction)) continue;
        const Eigen::Vector3d in_mirror = Eigen::Vector3d(0.0, 0.0, remap.settings.v0_mm) + distance_mm * direction;
        const Eigen::Vector3d in_camera = std::visit(
            [&](const auto& m) -> Eigen::Vector3d {
              return m.pose.CameraFromMirrorRotation() * in_mirror + m.pose.CameraFromMirrorTranslation();
            },
            sensor.model());
        Eigen::Vector2d pixel;
        if (sensor.Project(in_camera, &pixel) != omnical::ProjectionStatus::kOk) continue;
        worst_px = std::max(worst_px, (pixel - Eigen::Vector2d(table.map_x[k], table.map_y[k])).norm());
        ++checked;
      }
    std::printf("%d table entries checked against direct projection: worst %.2g px\n", checked, worst_px);

    const omnical::Unwarper unwarper(table, sensor.image_width_px(), sensor.image_height_px(),
                                     omnical::Interpolation::kLinear);
    const cv::Mat omni = cv::imread(argv[2], cv::IMREAD_GRAYSCALE);
    const cv::Mat panorama = unwarper.Apply(omni, argv[2]);
    omnical::WriteImageFile(argv[3], panorama);
    std::printf("%s: %d x %d\n", argv[3], panorama.cols, panorama.rows);
    return checked > 100 && worst_px < 0.01 ? 0 : 1;
  } catch (const omnical::InputError& error) {
    std::printf("error: %s\n", error.what());
    return 2;
  }
}
