#include "tools/python/py_image.h"

#include <string>

#include "model/input_error.h"

namespace omnical::python {

namespace py = pybind11;

cv::Mat MatOf(const py::handle& image, const char* name) {
  const std::string expected = std::string(name) + ": expected an (H, W) or (H, W, 1|3|4) uint8 image";
  if (!py::isinstance<py::array>(image))
    throw InputError(expected + ", got " + std::string(py::str(py::type::of(image).attr("__name__"))));
  const auto array = py::reinterpret_borrow<py::array>(image);
  if (array.dtype().kind() != 'u' || array.itemsize() != 1)
    throw InputError(expected + ", got dtype " + std::string(py::str(array.dtype())) + " (convert with astype(np.uint8))");
  const int channels = array.ndim() == 3 ? static_cast<int>(array.shape(2)) : 1;
  if ((array.ndim() != 2 && array.ndim() != 3) || (channels != 1 && channels != 3 && channels != 4) ||
      array.shape(0) == 0 || array.shape(1) == 0) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < array.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(array.shape(i));
    throw InputError(expected + ", got shape " + shape + (array.ndim() == 1 ? ",)" : ")"));
  }
  const int rows = static_cast<int>(array.shape(0)), cols = static_cast<int>(array.shape(1));
  const int type = CV_8UC(channels);
  // C-contiguous rows (any row pitch, e.g. a crop of a larger image) are used in place.
  const bool rows_packed = array.strides(1) == channels && (array.ndim() == 2 || array.strides(2) == 1) &&
                           array.strides(0) >= cols * channels;
  if (rows_packed)
    return cv::Mat(rows, cols, type, const_cast<void*>(array.data()), static_cast<size_t>(array.strides(0)));
  const auto packed = py::array_t<std::uint8_t, py::array::c_style>::ensure(array);
  return cv::Mat(rows, cols, type, const_cast<std::uint8_t*>(packed.data())).clone();
}

py::array ArrayOf(const cv::Mat& mat) {
  py::dtype dtype;
  switch (mat.depth()) {
    case CV_8U: dtype = py::dtype::of<std::uint8_t>(); break;
    case CV_16U: dtype = py::dtype::of<std::uint16_t>(); break;
    case CV_32F: dtype = py::dtype::of<float>(); break;
    case CV_64F: dtype = py::dtype::of<double>(); break;
    default: throw std::runtime_error("ArrayOf: unsupported cv::Mat depth " + std::to_string(mat.depth()));
  }
  auto* owned = new cv::Mat(mat);  // shares the buffer, holds a reference
  py::capsule owner(owned, [](void* p) { delete static_cast<cv::Mat*>(p); });
  const auto element = static_cast<py::ssize_t>(mat.elemSize1());
  std::vector<py::ssize_t> shape = {mat.rows, mat.cols}, strides = {static_cast<py::ssize_t>(mat.step[0]),
                                                                    static_cast<py::ssize_t>(mat.elemSize())};
  if (mat.channels() > 1) {
    shape.push_back(mat.channels());
    strides.push_back(element);
  }
  return py::array(dtype, shape, strides, owned->data, owner);
}

}  // namespace omnical::python
