// Whether the board's relief is fitted (BoardWarp::relief_mm: each corner's own
// out-of-plane offset on top of the paraboloid warp, shared by every view). A board whose
// shape the paraboloid cannot follow (a card bent at one corner) otherwise leaves that
// shape in every view's residuals, where the mirror and the lens bend to meet it; a board
// the paraboloid does describe gains nothing but a parameter per corner. So it is chosen
// by held-out folds (calib/fold_scores.h), the board shape learnt on the training views
// and held for the held-out ones: fitted only where that predicts the held-out views
// better by more than kReliefScoreTolerance (the other choices' parsimony rule).
// Measured on the real Mei set (docs/calibrate.md, "Bent boards"; from its images): held-out
// folds 0.310 -> 0.251 px, all corners 0.286 -> 0.216 px.
#pragma once

#include <string>
#include <vector>

namespace omnical {

// CalibrationOptions::board_relief: "" (the default), kReliefOff, kReliefOn or kChooseRelief.
inline constexpr const char* kReliefOff = "off";
inline constexpr const char* kReliefOn = "on";
inline constexpr const char* kChooseRelief = "auto";
// The candidates, the simpler first: the paraboloid warp alone, or with each corner's relief.
inline const std::vector<std::string> kReliefCandidates = {"warp", "warp+relief"};
constexpr double kReliefScoreTolerance = 0.01;

}  // namespace omnical
