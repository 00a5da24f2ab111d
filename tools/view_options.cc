#include "tools/view_options.h"

#include "tools/cli_common.h"

namespace omnical::cli {
namespace {

const char* const kViewOptionNames[] = {"--view",      "--size",     "--azimuth0-deg", "--elevation-deg", "--pan-deg",
                                        "--tilt-deg",  "--roll-deg", "--hfov-deg",     "--omega-max-deg", "--distance-mm",
                                        "--n",         "--infinity", "--surface",      "--plane-normal",  "--v0",
                                        "--per-pixel"};

}  // namespace

const FlagTable& ViewFlags() {
  static const FlagTable flags =
      FlagsOf({"view", "size", "azimuth0_deg", "elevation_deg", "pan_deg", "tilt_deg", "roll_deg", "hfov_deg",
               "omega_max_deg", "distance_mm", "n", "infinity", "surface", "plane_normal", "threads", "per_pixel"},
              {{"v0_mm", "--v0"}});
  return flags;
}

void AddViewOptions(CLI::App& sub, ViewRequest* options, bool required_view) {
  auto* view = sub.add_option("--view", options->view, "Virtual screen: panorama, lonlat, perspective, equiangular")
                   ->check(CLI::IsMember({"panorama", "lonlat", "perspective", "equiangular"}));
  if (required_view) view->required();
  sub.add_option("--size", options->size,
                 "Output size WxH px (default: panorama/lonlat 2048x512, perspective 800x600, equiangular 1000x1000)");
  sub.add_option("--azimuth0-deg", options->azimuth0_deg, "panorama/lonlat: azimuth of the left edge (deg)")->capture_default_str();
  sub.add_option("--elevation-deg", options->elevation_deg,
                 "panorama/lonlat: elevation of the top and bottom edges, 'top,bottom' (deg; default: the field)")
      ->delimiter(',')->expected(2);
  sub.add_option("--pan-deg", options->pan_deg, "perspective: azimuth of the optical axis (deg)");
  sub.add_option("--tilt-deg", options->tilt_deg, "perspective: elevation of the optical axis (deg)");
  sub.add_option("--roll-deg", options->roll_deg, "perspective: roll about the optical axis (deg)");
  sub.add_option("--hfov-deg", options->hfov_deg, "perspective: horizontal field of view (deg)");
  sub.add_option("--omega-max-deg", options->omega_max_deg, "equiangular: Omega at the disc's edge (deg; default: the rim's)");
  auto* distance = sub.add_option("--distance-mm", options->distance_mm, "Objects at this distance D from V0 (mm)");
  auto* n = sub.add_option("--n", options->n, "Objects at n mirror rim radii from V0");
  auto* infinity = sub.add_flag("--infinity", options->infinity, "Objects at infinity (the central approximation)");
  distance->excludes(n)->excludes(infinity);
  n->excludes(infinity);
  sub.add_option("--surface", options->surface,
                 "Object surface at the distance: sphere (around V0), cylinder (about the axis), plane")
      ->check(CLI::IsMember({"sphere", "cylinder", "plane"}));
  sub.add_option("--plane-normal", options->plane_normal, "plane: its normal 'x,y,z' in the mirror frame, from V0 towards it")
      ->delimiter(',')->expected(3);
  sub.add_option("--v0", options->v0_mm, "Viewpoint V0, z on the mirror axis (mm, mirror frame); "
                                         "default: the one minimising the worst error at the distance");
  sub.add_option("--threads", options->threads, "Threads (0: all cores)")->check(kNonNegative);
  sub.add_flag("--per-pixel", options->per_pixel,
               "Project every output pixel (no interpolated grid; its error bound is 0.01 px)");
  if (required_view) {
    sub.callback([distance, n, infinity]() {
      if (distance->count() + n->count() + infinity->count() == 0)
        throw CLI::RequiredError("--distance-mm, --n or --infinity");
    });
  }
}

bool AnyViewOptionGiven(const CLI::App& sub) {
  for (const char* name : kViewOptionNames)
    if (sub.count(name) > 0) return true;
  return false;
}

}  // namespace omnical::cli
