// What a detection or calibration run found questionable without failing: a typed code a
// program can act on, the image or parameter it concerns, and the one-line text a person
// reads (the CLI prints it after "omnical: warning: ").
#pragma once

#include <string>

namespace omnical {

enum class WarningCode {
  kImageUnreadable,           // subject: the image; skipped
  kImageSizeDiffers,          // subject: the image; skipped
  kCheckerboardRefused,       // subject: the image; a checkerboard-like grid that is not the target
  kViewSkipped,               // subject: the image; no target found, or too few usable corners for a starting pose
  kToleranceNotApplicable,    // subject: the parameter; the guess's tolerance does not fit the family
  kViewLeftOut,               // subject: the image; left out of the fit (why in the text)
  kSensorInvalid,             // the fitted sensor fails validation
  kNotConverged,              // the solver did not converge
  kFreeGauge,                 // the covariance could not be computed
  kWeaklyDetermined,          // subject: the parameter
  kOneDistance,               // every board at about one distance while the shape is free
  kToleranceConflict,         // a parameter ended far from its design value
  kToleranceNote,             // a tolerance the fit could not use
  kPredictedErrorUnknown,     // no field pixel projects at a distance
  kPredictedErrorHigh,        // the predicted projection error exceeds the threshold
  kHeldOutWorse,              // held-out views fit much worse than the training views
  kKnotCountReplaced,         // subject: knots; the folds' count fitted no valid mirror, the next was used
  kLensNotChosen,             // subject: lens; neither lens predicted every held-out fold, the orthographic kept
  kTangentialNotFitted,       // subject: tangential; asked for (on/auto, not by default) but not fitted: an orthographic lens chosen, or no candidate scored
  kBoardScreenStopped,        // the board-size screen would refuse more than a quarter of the views: it kept them
  kImageRimNotUsed,           // subject: rim_circle; the images' rim is not this fit's mirror rim: detection kept the fit's
  kProfileNotChosen,          // subject: profile; neither family predicted every held-out fold, the polynomial kept
};

// A stable lower-case name for programs (Python's CalibrationWarning.code), e.g.
// "predicted_error_high".
const char* WarningCodeName(WarningCode code);

struct CalibrationWarning {
  WarningCode code;
  std::string subject;  // image path or parameter name; empty if about the whole run
  std::string text;     // one line, complete
  std::string reason{};  // a skipped image's: why, alone (CalibrationRecord::views_skipped)
};

}  // namespace omnical
