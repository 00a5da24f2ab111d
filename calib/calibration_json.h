// calibration.json: a CalibrationRecord (calib/calibration_record.h) written as JSON and
// read back. Non-finite numbers are written as null (a std that is undetermined) or as
// "infinity" (the predicted error's infinite distance).
#pragma once

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

}  // namespace omnical
