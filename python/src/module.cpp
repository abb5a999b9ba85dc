// The Python module's entry point (python/saresgs/__init__.py re-exports it): each part of
// the API is bound in its own file.
#include <stdexcept>

#include "geometry/error.h"
#include "python/src/bindings.h"

namespace saresgs::python {

ImageF imageFromArray(const py::array& a, int channels, const std::string& what) {
  const auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!f) throw py::value_error(what + ": expected a float array");
  const bool ok =
      channels == 1 ? (f.ndim() == 2 || (f.ndim() == 3 && f.shape(2) == 1)) : (f.ndim() == 3 && f.shape(2) == channels);
  if (!ok)
    throw py::value_error(what + ": expected shape (H, W" +
                          (channels == 1 ? std::string(")") : ", " + std::to_string(channels) + ")") + ", got ndim " +
                          std::to_string(f.ndim()));
  ImageF img(static_cast<int>(f.shape(1)), static_cast<int>(f.shape(0)), channels);
  std::copy(f.data(), f.data() + img.data.size(), img.data.begin());
  return img;
}

void checkSignals() {
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

}  // namespace saresgs::python

PYBIND11_MODULE(_core, m) {
  namespace sp = saresgs::python;
  m.doc() = "saresgs: active 3D Gaussian Splatting on the CPU (the C++ libraries, bound with pybind11)";
  // The libraries' input errors (file, field, what was expected) arrive as ValueError.
  pybind11::register_exception<saresgs::InputError>(m, "InputError", PyExc_ValueError);
  sp::bindData(m);
  sp::bindModel(m);
  sp::bindTrain(m);
  sp::bindNbv(m);
}
