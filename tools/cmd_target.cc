// omnical target: a printable calibration target at true scale (PNG at a given dpi, SVG
// or PDF with the physical size), from a Kalibr-style spec.
#include <filesystem>

#include "calib/target.h"
#include "model/input_error.h"
#include "tools/commands.h"

namespace omnical::cli {

Command TargetCommand() {
  return {"target", "Write a printable target (png at --dpi, svg, pdf; true scale) from a Kalibr-style spec",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto spec = std::make_shared<std::string>();
            auto out = std::make_shared<std::string>();
            auto dpi = std::make_shared<double>(300.0);
            sub.add_option("--spec", *spec, "Target spec (YAML, Kalibr keys)")->required();
            sub.add_option("--out", *out, "Output file: .png, .svg or .pdf")->required();
            sub.add_option("--dpi", *dpi, "Resolution of a PNG, dots per inch")
                ->check(CLI::Range(10.0, 2400.0))
                ->capture_default_str();
            return [=, &context]() {
              const CalibrationTarget target = CalibrationTarget::FromYaml(*spec);
              const std::string extension = std::filesystem::path(*out).extension().string();
              if (extension == ".png") {
                target.WritePng(*out, *dpi);
              } else if (extension == ".svg") {
                target.WriteSvg(*out);
              } else if (extension == ".pdf") {
                target.WritePdf(*out);
              } else {
                throw InputError(InputMessage(*out, "--out", "unknown format '" + extension + "' (.png, .svg or .pdf)"));
              }
              if (!context.quiet) {
                const Eigen::Vector2d size = target.max_mm() - target.min_mm();
                std::printf("%s: %.1f x %.1f mm, %zu corners -> %s\n", spec->c_str(), size.x(), size.y(),
                            target.corners().size(), out->c_str());
              }
            };
          }};
}

}  // namespace omnical::cli
