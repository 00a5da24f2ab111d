#include "calib/calibration_warning.h"

namespace omnical {

const char* WarningCodeName(WarningCode code) {
  // No default: -Wswitch (an error with OMNICAL_WERROR) flags a code added without a name.
  switch (code) {
    case WarningCode::kImageUnreadable: return "image_unreadable";
    case WarningCode::kImageSizeDiffers: return "image_size_differs";
    case WarningCode::kCheckerboardRefused: return "checkerboard_refused";
    case WarningCode::kViewSkipped: return "view_skipped";
    case WarningCode::kToleranceNotApplicable: return "tolerance_not_applicable";
    case WarningCode::kViewLeftOut: return "view_left_out";
    case WarningCode::kSensorInvalid: return "sensor_invalid";
    case WarningCode::kNotConverged: return "not_converged";
    case WarningCode::kFreeGauge: return "free_gauge";
    case WarningCode::kWeaklyDetermined: return "weakly_determined";
    case WarningCode::kOneDistance: return "one_distance";
    case WarningCode::kToleranceConflict: return "tolerance_conflict";
    case WarningCode::kToleranceNote: return "tolerance_note";
    case WarningCode::kPredictedErrorUnknown: return "predicted_error_unknown";
    case WarningCode::kPredictedErrorHigh: return "predicted_error_high";
    case WarningCode::kHeldOutWorse: return "held_out_worse";
    case WarningCode::kKnotCountReplaced: return "knot_count_replaced";
    case WarningCode::kLensNotChosen: return "lens_not_chosen";
    case WarningCode::kTangentialNotFitted: return "tangential_not_fitted";
    case WarningCode::kBoardScreenStopped: return "board_screen_stopped";
    case WarningCode::kImageRimNotUsed: return "image_rim_not_used";
    case WarningCode::kProfileNotChosen: return "profile_not_chosen";
  }
  return "unknown";
}

}  // namespace omnical
