// What every binding file of the Python module shares: NumPy arrays in and out, the
// error mapping (InputError -> omnical.InputError, a ValueError, with the library's one
// line), and long calls run with the GIL released, a Python progress callback, and
// Ctrl-C turned into a clean cancellation.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <type_traits>
#include <string>
#include <utility>
#include <vector>

#include "model/progress.h"

namespace omnical::python {

namespace py = pybind11;

using RowsArray = py::array_t<double, py::array::c_style>;

// An (N, columns) array of numbers as C-contiguous float64 rows. Accepts any real dtype
// (float32 and integers are converted) and any strides (copied); C-contiguous float64
// is used in place. Anything else raises InputError "<name>: ..." (wrong shape,
// complex, strings, objects).
RowsArray RowsOf(const py::handle& array, int columns, const char* name);

// The rows as a K x N matrix, one point a column, without a copy.
template <int K>
Eigen::Map<const Eigen::Matrix<double, K, Eigen::Dynamic>> AsColumns(const RowsArray& rows) {
  return {rows.data(), K, static_cast<Eigen::Index>(rows.shape(0))};
}

// A K x N matrix handed to NumPy as an (N, K) float64 array without a copy (the array
// owns it).
template <int K>
py::array_t<double> RowsArrayOf(Eigen::Matrix<double, K, Eigen::Dynamic>&& columns) {
  using Matrix = Eigen::Matrix<double, K, Eigen::Dynamic>;
  auto* owned = new Matrix(std::move(columns));
  py::capsule owner(owned, [](void* p) { delete static_cast<Matrix*>(p); });
  return py::array_t<double>({static_cast<py::ssize_t>(owned->cols()), static_cast<py::ssize_t>(K)}, owned->data(), owner);
}

// A vector handed to NumPy without a copy.
template <typename T>
py::array_t<T> VectorArray(std::vector<T>&& values) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({static_cast<py::ssize_t>(owned->size())}, owned->data(), owner);
}

// The GIL released for the scope, as py::gil_scoped_release, except at interpreter exit:
// there CPython ends a daemon thread that takes the GIL back with pthread_exit, whose
// unwinding cannot pass C++ destructors; such a thread waits for the process to end
// instead (what CPython 3.14 itself does).
class GilReleased {
 public:
  GilReleased() : state_(PyEval_SaveThread()) {}
  ~GilReleased();
  GilReleased(const GilReleased&) = delete;
  GilReleased& operator=(const GilReleased&) = delete;

 private:
  PyThreadState* state_;
};

// A path argument: str or os.PathLike.
std::string PathOf(const py::handle& path);

// The callback a job gets: calls `progress(stage, done, total)` (if not None) with the
// GIL held; a falsy return other than None cancels, an exception is raised again from
// the call. It also returns false once SIGINT arrived during the call (RunReleased).
ProgressCallback ForwardProgress(py::object progress);

// True once the interpreter is shutting down: a worker thread must not take the GIL then
// (it would be ended inside the library's code).
bool Finalizing();

// Runs job() with the GIL released and Ctrl-C watched (on the main thread: a SIGINT
// handler chained to Python's sets a flag the progress callback returns), turning the
// library's Cancelled into KeyboardInterrupt when Ctrl-C caused it, else
// omnical.Cancelled.
void RunReleasedImpl(const std::function<void()>& job);
template <typename Job>
auto RunReleased(Job&& job) -> decltype(job()) {
  using Result = decltype(job());
  if constexpr (std::is_void_v<Result>) {
    RunReleasedImpl(job);
  } else {
    std::optional<Result> result;
    RunReleasedImpl([&] { result.emplace(job()); });
    return std::move(*result);
  }
}

}  // namespace omnical::python
