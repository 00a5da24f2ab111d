// Images between NumPy and OpenCV: (H, W) or (H, W, C) uint8 arrays (C = 3 or 4, BGR as
// cv2 has them) <-> cv::Mat. Any strides are accepted (copied); other dtypes refused.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <opencv2/core.hpp>

namespace omnical::python {

// Raises InputError "<name>: expected ..." for anything but a 2-D or 3-D uint8 array
// (1, 3 or 4 channels). The Mat refers to the array's memory when it is C-contiguous
// (keep `array` alive), else to a copy held by the Mat.
cv::Mat MatOf(const pybind11::handle& image, const char* name);

// The Mat as an array of the same shape and dtype (uint8, uint16, float32, float64); the
// array shares the Mat's buffer (no copy) and keeps it alive.
pybind11::array ArrayOf(const cv::Mat& mat);

}  // namespace omnical::python
