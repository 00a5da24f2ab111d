// A remap job's files: the table in the chosen formats (map_export.h) and maps.json
// describing it, each written atomically into an output directory.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "correction/maps_json.h"
#include "correction/remap_job.h"

namespace omnical {

enum class MapFormat { kOpenCv, kFfmpeg, kNpy };
// "opencv", "ffmpeg", "npy".
std::optional<MapFormat> ParseMapFormat(const std::string& name);

// Creates `dir`, writes the table in each of `formats` and then maps.json; returns what
// it wrote. Throws InputError naming the file that could not be written.
MapFiles WriteRemapOutputs(const std::string& dir, const RemapResult& result, const std::vector<MapFormat>& formats,
                           const SensorSource& sensor);

}  // namespace omnical
