// The figures of the correction jobs (PNG, written atomically): a remap table's error at
// other distances, the parallax curve and error map, a table's error sweep from disk, and
// a central export's error over the field.
#pragma once

#include <string>

#include "correction/central_export.h"
#include "correction/maps_error_report.h"
#include "correction/parallax_report.h"
#include "correction/remap_job.h"

namespace omnical {

// DIR/remap_error.png: the kSummary sweep's max and rms against log10 n.
void WriteRemapFigures(const std::string& dir, const RemapResult& result);
// DIR/parallax.png (the curve) and DIR/error_map.png (the map, false colour).
void WriteParallaxFigures(const std::string& dir, const ParallaxResult& result);
// DIR/maps-error.png: the kCurve sweep, with the error at infinity dashed.
void WriteMapsErrorFigures(const std::string& dir, const MapsErrorResult& result);
// DIR/central_error.png: each field sample's error against Omega.
void WriteCentralExportFigures(const std::string& dir, const CentralExportResult& result);

}  // namespace omnical
