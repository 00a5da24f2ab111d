// Planar calibration targets described with Kalibr's YAML keys, so a Kalibr spec file
// loads unchanged:
//   aprilgrid:    target_type: aprilgrid, tagCols, tagRows, tagSize (m, the black square's
//                 edge), tagSpacing (gap / tagSize), optional codeOffset (first tag id) and
//                 tagFamily (omnical's extension: tag36h11 (default) or tagStandard41h12).
//   checkerboard: target_type: checkerboard, targetCols, targetRows (inner corners),
//                 rowSpacingMeters, colSpacingMeters.
//
// Board frame (Kalibr's layout): origin at the bottom-left tag's bottom-left black corner
// (checkerboard: the bottom-left inner corner), x right along columns, y up along rows,
// z out of the printed face; lengths in mm. Tag ids increase along a row, then up the rows.
// Corner ids are stable: aprilgrid 4 * tag_id + k with k = 0 bottom-left, 1 bottom-right,
// 2 top-right, 3 top-left of the black square; checkerboard row * targetCols + col.
//
// omnical's printed aprilgrid keeps white gaps between tags (no black corner squares as in
// Kalibr's print), which the AprilTag 3 quad detector needs (apriltag issues 141, 328).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace omnical {

struct TargetCorner {
  int id;
  Eigen::Vector3d point_in_target;  // mm, z = 0
};

class CalibrationTarget {
 public:
  enum class Type { kAprilGrid, kCheckerboard };

  // Reads a Kalibr-style spec; throws InputError "file: field: problem".
  static CalibrationTarget FromYaml(const std::string& path);
  static CalibrationTarget AprilGrid(int cols, int rows, double tag_size_mm, double spacing_ratio,
                                     const std::string& family = "tag36h11", int code_offset = 0);
  static CalibrationTarget Checkerboard(int cols, int rows, double col_spacing_mm, double row_spacing_mm);

  Type type() const { return type_; }
  const std::string& family() const { return family_; }
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  int code_offset() const { return code_offset_; }
  double tag_size_mm() const { return tag_size_mm_; }
  double spacing_ratio() const { return spacing_ratio_; }
  const std::vector<TargetCorner>& corners() const { return corners_; }
  // What the corner ids and positions depend on, in words ("aprilgrid 6 x 6 tag36h11 from
  // id 0, 30 mm tags, spacing 0.3"): recorded with detections, so that corners are not
  // fitted to another board than the one they were found on.
  std::string Describe() const;

  // The printed board's extent in the board frame (mm), margins included.
  Eigen::Vector2d min_mm() const { return min_mm_; }
  Eigen::Vector2d max_mm() const { return max_mm_; }
  Eigen::Vector2d centre_mm() const { return 0.5 * (min_mm_ + max_mm_); }

  // Reflectance of the printed face at (x, y) mm: kInk or kPaper; negative outside the board.
  double Reflectance(double x_mm, double y_mm) const;
  static constexpr double kInk = 0.04;
  static constexpr double kPaper = 0.9;
  // Black cells of the print as rectangles (x, y, w, h in mm), merged along rows: the
  // printed face is kInk inside them and kPaper elsewhere on the board.
  std::vector<Eigen::Vector4d> InkRectangles() const;

  // Printable versions at true scale. PNG at `dpi`; SVG and PDF as vector rectangles with
  // the physical size. Written atomically; throw InputError on failure.
  void WritePng(const std::string& path, double dpi) const;
  void WriteSvg(const std::string& path) const;
  void WritePdf(const std::string& path) const;

 private:
  struct Bitmap {
    int size = 0;             // total width in bits
    int border = 0;           // width at the black border, in bits
    std::vector<uint8_t> white;  // size x size, row 0 at the top of the printed tag
  };
  void BuildCorners();

  Type type_ = Type::kCheckerboard;
  std::string family_;
  int cols_ = 0, rows_ = 0, code_offset_ = 0;
  double tag_size_mm_ = 0.0, spacing_ratio_ = 0.0;   // aprilgrid
  double col_spacing_mm_ = 0.0, row_spacing_mm_ = 0.0;  // checkerboard
  std::vector<Bitmap> bitmaps_;  // aprilgrid: one per tag
  std::vector<TargetCorner> corners_;
  Eigen::Vector2d min_mm_ = Eigen::Vector2d::Zero(), max_mm_ = Eigen::Vector2d::Zero();
};

}  // namespace omnical
