#include "correction/remap_outputs.h"

#include <algorithm>
#include <filesystem>

#include "correction/map_export.h"
#include "model/io/atomic_write.h"

namespace omnical {

std::optional<MapFormat> ParseMapFormat(const std::string& name) {
  if (name == "opencv") return MapFormat::kOpenCv;
  if (name == "ffmpeg") return MapFormat::kFfmpeg;
  if (name == "npy") return MapFormat::kNpy;
  return std::nullopt;
}

MapFiles WriteRemapOutputs(const std::string& dir, const RemapResult& result, const std::vector<MapFormat>& formats,
                           const SensorSource& sensor) {
  auto wanted = [&](MapFormat format) { return std::find(formats.begin(), formats.end(), format) != formats.end(); };
  CreateOutputDirectory(dir);
  const std::filesystem::path out(dir);
  const RemapTable& table = result.table;
  MapFiles files;
  if (wanted(MapFormat::kOpenCv)) {
    WriteOpenCvMaps(table, (out / "maps.yml.gz").string(), (out / "maps_fixed.yml.gz").string());
    files.opencv = true;
  }
  if (wanted(MapFormat::kFfmpeg)) {
    WriteFfmpegMaps(table, (out / "xmap.pgm").string(), (out / "ymap.pgm").string());
    files.ffmpeg = true;
    files.ffmpeg_command = "ffmpeg -i INPUT -i " + (out / "xmap.pgm").string() + " -i " + (out / "ymap.pgm").string() +
                           " -filter_complex \"[0:v][1:v][2:v]remap\" OUTPUT";
  }
  if (wanted(MapFormat::kNpy)) {
    WriteNpyMaps(table, (out / "map_x.npy").string(), (out / "map_y.npy").string());
    files.npy = true;
  }
  WriteMapsJson(dir, result, files, sensor);
  return files;
}

}  // namespace omnical
