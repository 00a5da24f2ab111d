#include "calib/target.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagStandard41h12.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "model/io/atomic_write.h"
#include "model/io/codecs/image_codecs.h"
#include "model/input_error.h"
#include "model/io/yaml_field_reader.h"

namespace omnical {
namespace {

struct FamilyHandle {
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

bool FindFamily(const std::string& name, FamilyHandle* handle) {
  if (name == "tag36h11") {
    *handle = {tag36h11_create, tag36h11_destroy};
    return true;
  }
  if (name == "tagStandard41h12") {
    *handle = {tagStandard41h12_create, tagStandard41h12_destroy};
    return true;
  }
  return false;
}

// Kalibr's counts and sizes (metres) on top of the shared reader.
int Count(const YamlFieldReader& reader, const YAML::Node& root, const std::string& key, int minimum) {
  const double value = reader.Number(root[key], key);
  if (value != std::floor(value) || value < minimum || value > 10000)
    reader.Fail(key, "must be a whole number >= " + std::to_string(minimum));
  return static_cast<int>(value);
}

double PositiveMetres(const YamlFieldReader& reader, const YAML::Node& root, const std::string& key) {
  const double value = reader.Number(root[key], key);
  if (!(value > 0.0)) reader.Fail(key, "must be > 0 (metres)");
  if (value > 100.0) reader.Fail(key, "must be <= 100 m (the spec is in metres, Kalibr's unit)");
  return value;
}

}  // namespace

CalibrationTarget CalibrationTarget::FromYaml(const std::string& path) {
  const YamlFieldReader reader(path);
  const YAML::Node root = reader.LoadFile();
  if (!root.IsMap()) reader.Fail("", "expected a map with target_type and its fields");
  try {
    const std::string type = reader.Text(root["target_type"], "target_type");
    if (type == "aprilgrid") {
      reader.RejectUnknown(root, "", {"target_type", "tagCols", "tagRows", "tagSize", "tagSpacing", "codeOffset", "tagFamily"});
      const std::string family = root["tagFamily"] ? reader.Text(root["tagFamily"], "tagFamily") : "tag36h11";
      FamilyHandle handle;
      if (!FindFamily(family, &handle)) reader.Fail("tagFamily", "unknown tag family '" + family + "' (tag36h11 or tagStandard41h12)");
      const int offset = root["codeOffset"] ? Count(reader, root, "codeOffset", 0) : 0;
      try {
        return AprilGrid(Count(reader, root, "tagCols", 1), Count(reader, root, "tagRows", 1),
                         1000.0 * PositiveMetres(reader, root, "tagSize"), reader.Number(root["tagSpacing"], "tagSpacing"),
                         family, offset);
      } catch (const std::invalid_argument& error) {
        throw InputError(path + ": " + error.what());  // the message names its field
      }
    }
    if (type == "checkerboard") {
      reader.RejectUnknown(root, "", {"target_type", "targetCols", "targetRows", "rowSpacingMeters", "colSpacingMeters"});
      return Checkerboard(Count(reader, root, "targetCols", 2), Count(reader, root, "targetRows", 2),
                          1000.0 * PositiveMetres(reader, root, "colSpacingMeters"),
                          1000.0 * PositiveMetres(reader, root, "rowSpacingMeters"));
    }
    reader.Fail("target_type", "unknown target type '" + type + "' (aprilgrid or checkerboard)");
  } catch (const YAML::Exception& error) {
    reader.Fail("", std::string("unexpected YAML structure: ") + error.what());
  }
}

CalibrationTarget CalibrationTarget::AprilGrid(int cols, int rows, double tag_size_mm, double spacing_ratio,
                                               const std::string& family, int code_offset) {
  CalibrationTarget target;
  target.type_ = Type::kAprilGrid;
  target.family_ = family;
  target.cols_ = cols;
  target.rows_ = rows;
  target.code_offset_ = code_offset;
  target.tag_size_mm_ = tag_size_mm;
  target.spacing_ratio_ = spacing_ratio;
  FamilyHandle handle;
  if (!FindFamily(family, &handle)) throw std::invalid_argument("tagFamily: unknown tag family '" + family + "'");
  apriltag_family_t* fam = handle.create();
  const int total = fam->total_width, border = fam->width_at_border;
  const double needed = static_cast<double>(total - border) / border;
  const uint32_t ncodes = fam->ncodes;
  if (!std::isfinite(spacing_ratio)) {
    handle.destroy(fam);
    throw std::invalid_argument("tagSpacing: must be a finite number");
  }
  if (!(spacing_ratio >= needed)) {
    handle.destroy(fam);
    char text[160];
    std::snprintf(text, sizeof text, "tagSpacing: %.3g is too small for %s: its printed bits need a gap of >= %.3g",
                  spacing_ratio, family.c_str(), needed);
    throw std::invalid_argument(text);
  }
  if (static_cast<long>(code_offset) + static_cast<long>(cols) * rows > static_cast<long>(ncodes)) {
    handle.destroy(fam);
    throw std::invalid_argument("tagCols: " + std::to_string(cols * rows) + " tags from codeOffset " +
                                std::to_string(code_offset) + " exceed the " + std::to_string(ncodes) +
                                " codes of " + family);
  }
  for (int i = 0; i < cols * rows; ++i) {
    image_u8_t* image = apriltag_to_image(fam, code_offset + i);
    Bitmap bitmap;
    bitmap.size = total;
    bitmap.border = border;
    for (int y = 0; y < image->height; ++y)
      for (int x = 0; x < image->width; ++x) bitmap.white.push_back(image->buf[y * image->stride + x] != 0);
    std::free(image->buf);  // image_u8_destroy is not exported by Debian's libapriltag
    std::free(image);
    target.bitmaps_.push_back(std::move(bitmap));
  }
  handle.destroy(fam);
  const double gap = tag_size_mm * spacing_ratio, pitch = tag_size_mm + gap;
  target.min_mm_ = Eigen::Vector2d(-gap, -gap);
  target.max_mm_ = Eigen::Vector2d((cols - 1) * pitch + tag_size_mm + gap, (rows - 1) * pitch + tag_size_mm + gap);
  target.BuildCorners();
  return target;
}

std::string CalibrationTarget::Describe() const {
  char text[200];
  if (type_ == Type::kAprilGrid)
    std::snprintf(text, sizeof text, "aprilgrid %d x %d %s from id %d, %.6g mm tags, spacing %.6g", cols_, rows_, family_.c_str(),
                  code_offset_, tag_size_mm_, spacing_ratio_);
  else
    std::snprintf(text, sizeof text, "checkerboard %d x %d corners, %.6g x %.6g mm squares", cols_, rows_, col_spacing_mm_,
                  row_spacing_mm_);
  return text;
}

CalibrationTarget CalibrationTarget::Checkerboard(int cols, int rows, double col_spacing_mm, double row_spacing_mm) {
  CalibrationTarget target;
  target.type_ = Type::kCheckerboard;
  target.cols_ = cols;
  target.rows_ = rows;
  target.col_spacing_mm_ = col_spacing_mm;
  target.row_spacing_mm_ = row_spacing_mm;
  // One square of white margin around the (cols + 1) x (rows + 1) squares.
  target.min_mm_ = Eigen::Vector2d(-2.0 * col_spacing_mm, -2.0 * row_spacing_mm);
  target.max_mm_ = Eigen::Vector2d((cols + 1) * col_spacing_mm, (rows + 1) * row_spacing_mm);
  target.BuildCorners();
  return target;
}

void CalibrationTarget::BuildCorners() {
  corners_.clear();
  if (type_ == Type::kCheckerboard) {
    for (int j = 0; j < rows_; ++j)
      for (int i = 0; i < cols_; ++i)
        corners_.push_back({j * cols_ + i, Eigen::Vector3d(i * col_spacing_mm_, j * row_spacing_mm_, 0.0)});
    return;
  }
  const double pitch = tag_size_mm_ * (1.0 + spacing_ratio_), s = tag_size_mm_;
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < cols_; ++c) {
      const int tag = code_offset_ + r * cols_ + c;
      const double x = c * pitch, y = r * pitch;
      const Eigen::Vector3d square[4] = {{x, y, 0.0}, {x + s, y, 0.0}, {x + s, y + s, 0.0}, {x, y + s, 0.0}};
      for (int k = 0; k < 4; ++k) corners_.push_back({4 * tag + k, square[k]});
    }
  }
}

double CalibrationTarget::Reflectance(double x_mm, double y_mm) const {
  if (!(x_mm >= min_mm_.x() && x_mm <= max_mm_.x() && y_mm >= min_mm_.y() && y_mm <= max_mm_.y())) return -1.0;
  if (type_ == Type::kCheckerboard) {
    if (x_mm < -col_spacing_mm_ || x_mm >= cols_ * col_spacing_mm_ || y_mm < -row_spacing_mm_ ||
        y_mm >= rows_ * row_spacing_mm_)
      return kPaper;
    const int a = static_cast<int>(std::floor(x_mm / col_spacing_mm_)) + 1;
    const int b = static_cast<int>(std::floor(y_mm / row_spacing_mm_)) + 1;
    return (a + b) % 2 == 0 ? kInk : kPaper;
  }
  const Bitmap& first = bitmaps_.front();
  const double s = tag_size_mm_, pitch = s * (1.0 + spacing_ratio_);
  const double cell = s / first.border;
  const double outside = 0.5 * (first.size - first.border) * cell;  // bitmap beyond the black square
  const int c = static_cast<int>(std::floor((x_mm + outside) / pitch));
  const int r = static_cast<int>(std::floor((y_mm + outside) / pitch));
  if (c < 0 || c >= cols_ || r < 0 || r >= rows_) return kPaper;
  const double u = x_mm - (c * pitch - outside), v = y_mm - (r * pitch - outside);
  const int column = static_cast<int>(std::floor(u / cell));
  const int row_from_bottom = static_cast<int>(std::floor(v / cell));
  const Bitmap& bitmap = bitmaps_[r * cols_ + c];
  if (column < 0 || column >= bitmap.size || row_from_bottom < 0 || row_from_bottom >= bitmap.size) return kPaper;
  return bitmap.white[(bitmap.size - 1 - row_from_bottom) * bitmap.size + column] ? kPaper : kInk;
}

std::vector<Eigen::Vector4d> CalibrationTarget::InkRectangles() const {
  std::vector<Eigen::Vector4d> rects;
  if (type_ == Type::kCheckerboard) {
    for (int b = 0; b <= rows_; ++b)
      for (int a = 0; a <= cols_; ++a)
        if ((a + b) % 2 == 0)
          rects.emplace_back((a - 1) * col_spacing_mm_, (b - 1) * row_spacing_mm_, col_spacing_mm_, row_spacing_mm_);
    return rects;
  }
  const double s = tag_size_mm_, pitch = s * (1.0 + spacing_ratio_);
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < cols_; ++c) {
      const Bitmap& bitmap = bitmaps_[r * cols_ + c];
      const double cell = s / bitmap.border, outside = 0.5 * (bitmap.size - bitmap.border) * cell;
      for (int row = 0; row < bitmap.size; ++row) {
        const double y = r * pitch - outside + (bitmap.size - 1 - row) * cell;
        for (int column = 0; column < bitmap.size;) {
          if (bitmap.white[row * bitmap.size + column]) {
            ++column;
            continue;
          }
          int end = column;
          while (end < bitmap.size && !bitmap.white[row * bitmap.size + end]) ++end;
          rects.emplace_back(c * pitch - outside + column * cell, y, (end - column) * cell, cell);
          column = end;
        }
      }
    }
  }
  return rects;
}

void CalibrationTarget::WritePng(const std::string& path, double dpi) const {
  const double mm_per_px = 25.4 / dpi;
  const Eigen::Vector2d size = max_mm_ - min_mm_;
  const int width = static_cast<int>(std::lround(size.x() / mm_per_px));
  const int height = static_cast<int>(std::lround(size.y() / mm_per_px));
  if (width < 1 || height < 1 || static_cast<double>(width) * height > 4e8)
    throw InputError(InputMessage(path, "dpi", "gives an image of " + std::to_string(width) + " x " +
                                                     std::to_string(height) + " px"));
  cv::Mat image(height, width, CV_8UC1);
  constexpr int kSub = 4;  // 4 x 4 samples per pixel: cell edges that fall inside a pixel are grey
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double sum = 0.0;
      for (int j = 0; j < kSub; ++j)
        for (int i = 0; i < kSub; ++i) {
          const double x = min_mm_.x() + (u + (i + 0.5) / kSub) * mm_per_px;
          const double y = max_mm_.y() - (v + (j + 0.5) / kSub) * mm_per_px;
          sum += Reflectance(x, y) < 0.5 ? 0.0 : 1.0;
        }
      image.at<uchar>(v, u) = cv::saturate_cast<uchar>(255.0 * sum / (kSub * kSub));
    }
  }
  std::vector<uchar> bytes;
  if (!EncodeImage(".png", image, &bytes, {cv::IMWRITE_PNG_COMPRESSION, 9}))
    throw InputError(InputMessage(path, "", "cannot encode PNG"));
  WriteFileAtomically(path, [&](std::ostream& out) { out.write(reinterpret_cast<const char*>(bytes.data()), bytes.size()); });
}

void CalibrationTarget::WriteSvg(const std::string& path) const {
  const Eigen::Vector2d size = max_mm_ - min_mm_;
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.precision(10);
    out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size.x() << "mm\" height=\"" << size.y()
        << "mm\" viewBox=\"0 0 " << size.x() << ' ' << size.y() << "\">\n"
        << "<rect x=\"0\" y=\"0\" width=\"" << size.x() << "\" height=\"" << size.y() << "\" fill=\"white\"/>\n";
    for (const Eigen::Vector4d& r : InkRectangles()) {
      // SVG's y runs down the page; the board's y runs up.
      out << "<rect x=\"" << r(0) - min_mm_.x() << "\" y=\"" << max_mm_.y() - (r(1) + r(3)) << "\" width=\"" << r(2)
          << "\" height=\"" << r(3) << "\" fill=\"black\"/>\n";
    }
    out << "</svg>\n";
  });
}

void CalibrationTarget::WritePdf(const std::string& path) const {
  // A one-page PDF with filled rectangles; 1 mm = 72 / 25.4 pt, origin bottom-left like
  // the board frame.
  constexpr double kPt = 72.0 / 25.4;
  const Eigen::Vector2d size = (max_mm_ - min_mm_) * kPt;
  std::ostringstream content;
  content.precision(10);
  content << "0 g\n";
  for (const Eigen::Vector4d& r : InkRectangles())
    content << (r(0) - min_mm_.x()) * kPt << ' ' << (r(1) - min_mm_.y()) * kPt << ' ' << r(2) * kPt << ' '
            << r(3) * kPt << " re f\n";
  const std::string stream = content.str();
  std::ostringstream pdf;
  pdf.precision(10);
  std::vector<long> offsets;
  auto object = [&](const std::string& body) {
    offsets.push_back(static_cast<long>(pdf.tellp()));
    pdf << offsets.size() << " 0 obj\n" << body << "\nendobj\n";
  };
  pdf << "%PDF-1.4\n";
  object("<< /Type /Catalog /Pages 2 0 R >>");
  object("<< /Type /Pages /Kids [3 0 R] /Count 1 >>");
  std::ostringstream page;
  page.precision(10);
  page << "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 " << size.x() << ' ' << size.y() << "] /Contents 4 0 R >>";
  object(page.str());
  object("<< /Length " + std::to_string(stream.size()) + " >>\nstream\n" + stream + "endstream");
  const long xref = static_cast<long>(pdf.tellp());
  pdf << "xref\n0 " << offsets.size() + 1 << "\n0000000000 65535 f \n";
  for (long offset : offsets) {
    char line[24];
    std::snprintf(line, sizeof line, "%010ld 00000 n \n", offset);
    pdf << line;
  }
  pdf << "trailer\n<< /Size " << offsets.size() + 1 << " /Root 1 0 R >>\nstartxref\n" << xref << "\n%%EOF\n";
  const std::string bytes = pdf.str();
  WriteFileAtomically(path, [&](std::ostream& out) { out << bytes; });
}

}  // namespace omnical
