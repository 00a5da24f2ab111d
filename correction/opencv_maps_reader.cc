// ReadOpenCvMaps (declared in map_export.h) without cv::FileStorage: OpenCV 4.6's YAML
// parser never returns on some damaged files (tests/fuzz found a 36-byte one, kept as
// tests/data/fuzz-crashes/maps_yml-opencv-filestorage-hang.yml), so `unwarp --maps` would
// hang on a damaged maps.yml.gz. maps.yml.gz is omnical's own file: this reader accepts the
// layout cv::FileStorage writes for float matrices (what remap writes, and what Python's
// cv2.FileStorage writes for float32 arrays) and nothing else, line by line, with a bound
// on every line and every allocation.
#include <zlib.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "correction/map_export.h"
#include "model/input_error.h"

namespace omnical {
namespace {

// The largest virtual screen side omnical writes (remap --size allows 2..20000).
constexpr int kMaxMapSidePx = 20000;
// cv::FileStorage wraps data lines near 80 characters; anything far longer is not its output,
// and the bound keeps a damaged file from growing one line without limit.
constexpr size_t kMaxLineBytes = 4096;
// Doubles from here on round to float infinity (FLT_MAX plus half its last place); the
// text OpenCV writes for FLT_MAX, 3.40282347e+38, lies just above FLT_MAX and below this.
constexpr double kFloatOverflowBound = 0x1.ffffffp+127;

// Lines of a gzip file, or of a plain one (zlib reads those transparently).
class GzipLines {
 public:
  explicit GzipLines(const std::string& path) : path_(path), file_(gzopen(path.c_str(), "rb"), &gzclose) {
    if (!file_) throw InputError(InputMessage(path, "", "cannot be read (missing or unreadable)"));
    gzbuffer(file_.get(), 1 << 17);
  }

  // The next line without its '\n' (and '\r'); false at the end of the file.
  bool Next(std::string* line) {
    line->clear();
    ++line_number_;
    for (;;) {
      if (position_ == buffer_.size() && !Fill()) {
        if (line->empty()) {
          --line_number_;
          return false;
        }
        break;
      }
      const char* begin = buffer_.data() + position_;
      const size_t available = buffer_.size() - position_;
      const void* newline = std::memchr(begin, '\n', available);
      const size_t taken = newline ? static_cast<size_t>(static_cast<const char*>(newline) - begin) : available;
      line->append(begin, taken);
      position_ += taken + (newline ? 1 : 0);
      if (line->size() > kMaxLineBytes) Fail("is longer than " + std::to_string(kMaxLineBytes) + " bytes");
      if (newline) break;
    }
    if (!line->empty() && line->back() == '\r') line->pop_back();
    if (line->find('\0') != std::string::npos) Fail("holds a NUL byte (not a text file)");
    return true;
  }

  // A problem with the line last read (or being read).
  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(InputMessage(path_, "line " + std::to_string(line_number_), problem));
  }
  const std::string& path() const { return path_; }

 private:
  bool Fill() {
    buffer_.resize(1 << 16);
    const int read = gzread(file_.get(), buffer_.data(), static_cast<unsigned>(buffer_.size()));
    int code = Z_OK;
    const char* message = gzerror(file_.get(), &code);
    if (read < 0 || (code != Z_OK && code != Z_STREAM_END))
      throw InputError(InputMessage(path_, "", std::string("cannot be decompressed: ") + (message ? message : "gzip error")));
    buffer_.resize(static_cast<size_t>(read));
    position_ = 0;
    return read > 0;
  }

  std::string path_;
  std::unique_ptr<gzFile_s, int (*)(gzFile)> file_;
  std::vector<char> buffer_;
  size_t position_ = 0;
  int line_number_ = 0;
};

std::string Trimmed(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

// "KEY: VALUE" on an indented line; the value, or a failure naming what was expected.
std::string KeyValue(GzipLines& lines, const std::string& matrix, const std::string& key) {
  std::string line;
  if (!lines.Next(&line)) throw InputError(InputMessage(lines.path(), matrix, "ends before its " + key));
  if (line.empty() || (line[0] != ' ' && line[0] != '\t')) lines.Fail(matrix + ": expected an indented `" + key + ":`");
  const std::string entry = Trimmed(line);
  if (entry.compare(0, key.size() + 1, key + ":") != 0) lines.Fail(matrix + ": expected `" + key + ":`, found `" + entry.substr(0, 40) + "`");
  return Trimmed(entry.substr(key.size() + 1));
}

int SidePx(GzipLines& lines, const std::string& matrix, const std::string& key) {
  const std::string text = KeyValue(lines, matrix, key);
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value < 1 || value > kMaxMapSidePx)
    throw InputError(InputMessage(lines.path(), matrix + "." + key, "must be a whole number 1.." + std::to_string(kMaxMapSidePx) + ", is `" + text.substr(0, 40) + "`"));
  return value;
}

struct FloatMatrix {
  int rows = 0, cols = 0;
  std::vector<float> values;
};

// rows, cols, dt: f, and data: [ v, v, ... ] over as many lines as it takes.
FloatMatrix ReadMatrix(GzipLines& lines, const std::string& name) {
  FloatMatrix matrix;
  matrix.rows = SidePx(lines, name, "rows");
  matrix.cols = SidePx(lines, name, "cols");
  const std::string type = KeyValue(lines, name, "dt");
  if (type != "f") throw InputError(InputMessage(lines.path(), name + ".dt", "must be f (float32 maps), is `" + type.substr(0, 40) + "`"));
  const size_t count = static_cast<size_t>(matrix.rows) * static_cast<size_t>(matrix.cols);
  // Grown as values arrive, so a header promising more than the file holds allocates nothing.
  matrix.values.reserve(std::min<size_t>(count, 1 << 20));
  std::string rest = KeyValue(lines, name, "data");
  if (rest.empty() || rest[0] != '[') throw InputError(InputMessage(lines.path(), name + ".data", "must start with `[`"));
  rest.erase(0, 1);
  for (;;) {
    size_t start = 0;
    while (start < rest.size()) {
      const size_t comma = rest.find_first_of(",]", start);
      const std::string token = Trimmed(rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      const bool closing = comma != std::string::npos && rest[comma] == ']';
      if (!token.empty()) {
        if (matrix.values.size() == count) throw InputError(InputMessage(lines.path(), name + ".data", "holds more than rows x cols = " + std::to_string(count) + " values"));
        // As double, then rounded to float: what cv::FileStorage does (strtod), so values
        // read back equal OpenCV's to the bit, subnormals included.
        double value = 0;
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (error != std::errc() || end != token.data() + token.size() || !(std::abs(value) < kFloatOverflowBound))
          throw InputError(InputMessage(lines.path(), name + ".data", "value " + std::to_string(matrix.values.size() + 1) + " is not a finite number: `" + token.substr(0, 40) + "`"));
        matrix.values.push_back(static_cast<float>(value));
      } else if (comma != std::string::npos && rest[comma] == ',') {
        throw InputError(InputMessage(lines.path(), name + ".data", "an empty value after value " + std::to_string(matrix.values.size())));
      }
      if (closing) {
        if (!Trimmed(rest.substr(comma + 1)).empty()) lines.Fail(name + ".data: text after the closing `]`");
        if (matrix.values.size() != count)
          throw InputError(InputMessage(lines.path(), name + ".data", "holds " + std::to_string(matrix.values.size()) + " values, rows x cols = " + std::to_string(count)));
        return matrix;
      }
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (!lines.Next(&rest)) throw InputError(InputMessage(lines.path(), name + ".data", "ends before its closing `]`"));
  }
}

}  // namespace

RemapTable ReadOpenCvMaps(const std::string& float_path) {
  GzipLines lines(float_path);
  std::string line;
  if (!lines.Next(&line) || line != "%YAML:1.0")
    throw InputError(InputMessage(float_path, "", "not an OpenCV YAML storage file (no `%YAML:1.0` first line)"));
  if (!lines.Next(&line) || line != "---") lines.Fail("expected `---`");
  std::map<std::string, FloatMatrix> matrices;
  while (lines.Next(&line)) {
    if (Trimmed(line).empty()) continue;
    const size_t colon = line.find(':');
    const std::string name = line.substr(0, colon);
    if (line[0] == ' ' || line[0] == '\t' || colon == std::string::npos || colon == 0 || Trimmed(line.substr(colon + 1)) != "!!opencv-matrix")
      lines.Fail("expected `NAME: !!opencv-matrix`, found `" + line.substr(0, 40) + "`");
    if (matrices.count(name)) lines.Fail(name + " appears twice");
    matrices[name] = ReadMatrix(lines, name);
  }
  for (const char* name : {"map_x", "map_y"})
    if (!matrices.count(name)) throw InputError(InputMessage(float_path, name, "missing"));
  FloatMatrix& map_x = matrices["map_x"];
  FloatMatrix& map_y = matrices["map_y"];
  if (map_x.rows != map_y.rows || map_x.cols != map_y.cols)
    throw InputError(InputMessage(float_path, "map_x/map_y", "not two maps of one size"));
  RemapTable table;
  table.width = map_x.cols;
  table.height = map_x.rows;
  table.map_x = std::move(map_x.values);
  table.map_y = std::move(map_y.values);
  for (size_t i = 0; i < table.map_x.size(); ++i) table.valid_pixels += table.map_x[i] >= -0.5f && table.map_y[i] >= -0.5f;
  return table;
}

}  // namespace omnical
