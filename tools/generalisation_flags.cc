#include "tools/generalisation_flags.h"

#include "tools/cli_common.h"

namespace omnical::cli {

void AddGeneralisationFlags(CLI::App& sub, CalibrationOptions* library) {
  sub.add_option("--holdout", library->holdout_views,
                 "Keep K views (spread evenly) out of the fit and report their RMS with the sensor held (their poses "
                 "fitted): how well the calibration predicts new views")
      ->check(CLI::Range(0, 10000));
  sub.add_option("--holdout-folds", library->holdout_folds,
                 "Hold every view out once, K at a time: one more calibration per fold, each fold's views evaluated "
                 "with its sensor held; pooled in calibration.json holdout_folds (the written calibration is the full "
                 "set's)")
      ->check(CLI::Range(0, 10000));
  sub.add_flag("--cross-validate", library->cross_validate,
               "Also calibrate each half of the views (even / odd) and report how far the two disagree over the "
               "observed field after the best rigid alignment (report/cross_validation.png)");
  sub.add_option("--cross-validate-distance-mm", library->cross_validation_distance_mm,
                 "Distance of the cross-validation comparison (mm from the reflection point; default: the first "
                 "--distance-mm / --distance-n, else 2000)")
      ->check(kPositive);
  sub.add_option("--lens", library->lens, "Without a guess: the lens the rim circle starts: auto (the one predicting "
                 "held-out folds of the views better, calibration.json lens_choice; needs 4 usable views), "
                 "orthographic (telecentric) or pinhole (a perspective camera; with a free-form mirror m and "
                 "decenter held as gauges). Unset: as auto, the orthographic with under 4 views")
      ->check(CLI::IsMember({"orthographic", "pinhole", "auto"}));
  sub.add_option("--tangential", library->tangential,
                 "A pinhole's tangential distortion p1, p2 (a decentred lens): off (held at the start's values; "
                 "the default with a guess), on (fitted) or auto (the default without one): fitted only where that "
                 "predicts held-out folds better by > 1 % (calibration.json tangential_choice)")
      ->check(CLI::IsMember({"off", "on", "auto"}));
  sub.add_option("--board-relief", library->board_relief,
                 "The board's relief: each corner's own out-of-plane offset on top of the warp, shared by every view "
                 "(a card bent at one corner): off, on (fitted) or auto (the default without a guess): fitted only "
                 "where that predicts held-out folds better by > 1 % (calibration.json relief_choice)")
      ->check(CLI::IsMember({"off", "on", "auto"}));
  sub.add_flag("--leave-one-out", library->leave_one_out,
               "Also fit without each image in turn; calibration.json gets each parameter's spread");
}

}  // namespace omnical::cli
