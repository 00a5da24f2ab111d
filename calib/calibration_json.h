// calibration.json: a CalibrationRecord (calib/calibration_record.h) written as JSON and
// read back. Non-finite numbers are written as null (a std that is undetermined) or as
// "infinity" (the predicted error's infinite distance).
#pragma once

#include <map>
#include <string>

#include "calib/calibration_record.h"

namespace omnical {

// The JSON text (2-space indented, one trailing newline).
std::string CalibrationJsonText(const CalibrationRecord& record);
// Written atomically; throws InputError naming the path.
void WriteCalibrationJson(const CalibrationRecord& record, const std::string& path);
// Throws InputError "path: field: problem".
CalibrationRecord ReadCalibrationJson(const std::string& path);
CalibrationRecord ParseCalibrationJson(const std::string& text, const std::string& name);

// A projection difference (calib/projection_diff.h) as omnical diff writes it: the
// summary, `labels` (e.g. "a", "b", "field": what was compared), and per field pixel the
// pixel and its difference. Written atomically; throws InputError naming the path.
void WriteProjectionDiffJson(const ProjectionDiff& diff, const std::map<std::string, std::string>& labels,
                             const std::string& path);

}  // namespace omnical
