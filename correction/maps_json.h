// maps.json: the complete description of a remap table on disk (view geometry with the
// formula from output pixel to viewing direction, sensor, object surface, V0, the files,
// how exact the table is and how wrong at other distances), written by `remap` and read
// back by `unwarp --maps` and `parallax --maps`.
#pragma once

#include <string>

#include "correction/remap_job.h"
#include "correction/remap_table.h"

namespace omnical {

// The table files beside maps.json (fixed names: maps.yml.gz + maps_fixed.yml.gz,
// xmap.pgm + ymap.pgm, map_x.npy + map_y.npy).
struct MapFiles {
  bool opencv = false, ffmpeg = false, npy = false;
  std::string ffmpeg_command;  // with ffmpeg: the command line that applies xmap/ymap
};

// The sensor as the user gave it: its file name and text, kept in maps.json so that the
// directory stands alone.
struct SensorSource {
  std::string file, yaml;
};

// Writes DIR/maps.json atomically (InputError naming the file if that fails).
void WriteMapsJson(const std::string& dir, const RemapResult& result, const MapFiles& files, const SensorSource& sensor);

struct MapsDescription {
  std::string dir, path;  // path: DIR/maps.json
  RemapSettings settings;  // threads: 1
  std::string sensor_yaml;
  int sensor_width_px = 0, sensor_height_px = 0;  // 0: not in the file (sensor.image_size_px)
  std::string surface_json;  // the file's "surface" entry, JSON text, as written
};

// Reads DIR/maps.json (and DIR/maps.yml.gz into `table` when given, checking their sizes
// agree): throws InputError naming the file and field.
MapsDescription ReadMapsDescription(const std::string& dir, RemapTable* table = nullptr);

}  // namespace omnical
