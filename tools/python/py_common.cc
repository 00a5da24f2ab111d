#include "tools/python/py_common.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <string>
#include <thread>

#include "model/input_error.h"

namespace omnical::python {
namespace {

// Set by the SIGINT handler while a long call runs; read by every progress callback.
std::atomic<bool> g_interrupted{false};
struct sigaction g_python_sigint;  // Python's own handler, chained to

void OnSigint(int signal) {
  g_interrupted = true;
  // Python's C handler only records the signal (async-signal-safe); its Python-level
  // handler (KeyboardInterrupt, or the user's) runs once the call has returned.
  if (g_python_sigint.sa_handler != SIG_DFL && g_python_sigint.sa_handler != SIG_IGN)
    g_python_sigint.sa_handler(signal);
}

bool OnMainThread() {
  const py::object threading = py::module_::import("threading");
  return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

std::string ShapeText(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) text += (i ? ", " : "") + std::to_string(array.shape(i));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

// While a long call runs on the main thread, SIGINT also sets g_interrupted, which every
// progress callback reads (a Ctrl-C stops the jobs of other threads running meanwhile too:
// it means stop). Not installed when Python ignores SIGINT or leaves it at the default
// action (the user's choice stands), nor for calls from other threads (only the main
// thread gets KeyboardInterrupt; they stop through their progress callback), nor for
// nested calls (a callback calling omnical keeps the outer watch).
class SigintWatch {
 public:
  SigintWatch() {
    // Counted on the main thread only: another thread's call running meanwhile must not
    // make a main-thread call look nested.
    if (!OnMainThread()) return;
    counted_ = true;
    if (depth_++ != 0) return;
    struct sigaction current = {};
    sigaction(SIGINT, nullptr, &current);
    if (current.sa_handler == SIG_IGN || current.sa_handler == SIG_DFL || (current.sa_flags & SA_SIGINFO)) return;
    g_interrupted = false;
    struct sigaction ours = {};
    ours.sa_handler = OnSigint;
    sigemptyset(&ours.sa_mask);
    sigaction(SIGINT, &ours, &g_python_sigint);
    active_ = true;
  }
  ~SigintWatch() {
    if (counted_) --depth_;
    if (!active_) return;
    sigaction(SIGINT, &g_python_sigint, nullptr);
    g_interrupted = false;  // no stale flag for later calls
  }
  bool interrupted() const { return active_ && g_interrupted; }

 private:
  static inline int depth_ = 0;  // main-thread calls in progress; guarded by the GIL
  bool counted_ = false, active_ = false;
};

}  // namespace

bool Finalizing() {
#if PY_VERSION_HEX >= 0x030D0000
  return Py_IsFinalizing();
#else
  return _Py_IsFinalizing();
#endif
}

GilReleased::~GilReleased() {
  if (Finalizing())
    for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
  PyEval_RestoreThread(state_);
}

RowsArray RowsOf(const py::handle& object, int columns, const char* name) {
  const std::string expected = std::string(name) + ": expected an (N, " + std::to_string(columns) + ") array of numbers";
  py::array array;
  try {
    array = py::array::ensure(object);
  } catch (const py::error_already_set&) {
  }
  if (!array) throw InputError(expected + ", got " + std::string(py::str(py::type::of(object).attr("__name__"))));
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw InputError(expected + ", got dtype " + std::string(py::str(array.dtype())));
  if (array.ndim() != 2 || array.shape(1) != columns) {
    std::string hint;
    if (array.ndim() == 1 && array.shape(0) == columns)
      hint = " (one point: reshape(1, " + std::to_string(columns) + "))";
    throw InputError(expected + ", got shape " + ShapeText(array) + hint);
  }
  // float32, integers and non-contiguous views: one converting copy into C order.
  RowsArray rows = RowsArray::ensure(array);
  if (!rows) {  // the copy failed: ensure() clears the error, which can only be memory here
    PyErr_NoMemory();
    throw py::error_already_set();
  }
  return rows;
}

std::string PathOf(const py::handle& path) {
  const py::object os = py::module_::import("os");
  std::string text;
  try {
    text = py::str(os.attr("fspath")(path));
  } catch (const py::error_already_set&) {
    throw InputError("expected a path (str or os.PathLike), got " +
                     std::string(py::str(py::type::of(path).attr("__name__"))));
  }
  // The C++ side would read the path only up to the NUL: another file.
  if (text.find('\0') != std::string::npos) throw InputError(text.substr(0, text.find('\0')) + ": path contains a NUL character");
  return text;
}

ProgressCallback ForwardProgress(py::object progress) {
  if (progress.is_none()) return [](const ProgressUpdate&) { return !g_interrupted.load(); };
  // Shared so that copies of the callback made without the GIL do not touch the
  // reference count; released with the GIL held.
  auto callback = std::shared_ptr<py::object>(new py::object(std::move(progress)), [](py::object* p) {
    py::gil_scoped_acquire gil;
    delete p;
  });
  return [callback](const ProgressUpdate& update) {
    // A daemon thread's job while the interpreter exits: taking the GIL would end the
    // thread from inside the library; stop the job instead.
    if (g_interrupted || Finalizing()) return false;
    py::gil_scoped_acquire gil;
    const py::object answer = (*callback)(update.stage, update.done, update.total);
    if (answer.is_none()) return true;
    const int truth = PyObject_IsTrue(answer.ptr());
    if (truth < 0) throw py::error_already_set();  // its __bool__ raised: the caller gets that
    return truth == 1;
  };
}

void RunReleasedImpl(const std::function<void()>& job) {
  SigintWatch watch;
  try {
    GilReleased release;
    job();
    return;
  } catch (const Cancelled&) {
    if (!watch.interrupted()) throw;  // the callback said stop: omnical.Cancelled
  }
  // Python's handler saw the signal too: let it raise (KeyboardInterrupt by default); a
  // handler of the user's that does not raise leaves the job cancelled.
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  throw Cancelled("an interrupt (SIGINT)");
}

}  // namespace omnical::python
