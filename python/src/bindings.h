#pragma once
// The pieces of the Python module (python/src/*.cpp), one per room of the library, and the
// conversions they share. Arrays cross as NumPy arrays: images as H x W x C (H x W for one
// channel) float32 or uint8, cameras' matrices as float64, model parameters as float32
// views of the model's own storage.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/image/image.h"
#include "geometry/settings_table.h"
#include "geometry/scene/background.h"
#include "geometry/scene/scene.h"

namespace saresgs::python {

namespace py = pybind11;

void bindData(py::module_& m);   // cameras, datasets, built-in scenes (bind_data.cpp)
void bindModel(py::module_& m);  // Gaussians, render, gradients, loss, metrics (bind_model.cpp)
void bindTrain(py::module_& m);  // Trainer (bind_train.cpp)
void bindNbv(py::module_& m);    // scores, coverage, ActiveRun (bind_nbv.cpp)

// A NumPy array that owns `v` (moved, not copied), of the given shape.
template <typename T>
py::array_t<T> ownedArray(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* holder = new std::vector<T>(std::move(v));
  py::capsule owner(holder, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(std::move(shape), holder->data(), owner);
}

// An image as H x W x C (H x W when it has one channel), owning its pixels.
template <typename T>
py::array_t<T> imageArray(ImageT<T>&& img) {
  std::vector<py::ssize_t> shape{img.height, img.width};
  if (img.channels != 1) shape.push_back(img.channels);
  return ownedArray(std::move(img.data), std::move(shape));
}

// A float image from an H x W x C or H x W array (C = `channels`); throws ValueError
// naming `what` and the shape expected.
ImageF imageFromArray(const py::array& a, int channels, const std::string& what);

// The `background=` keyword: None (what the data says), "white", "black", "random", an
// "R,G,B" string, or three numbers in 0..1; anything else raises naming "background".
std::optional<BackgroundChoice> backgroundArg(const py::object& value);

// `dataset` itself without `background`, else a copy of it with that background (its
// images read again, composited on it): what Trainer and ActiveRun hold.
std::shared_ptr<Scene> withBackground(const std::shared_ptr<Scene>& dataset, const py::object& background);

// Raises the pending Python exception (KeyboardInterrupt on Ctrl-C) in C++, so that a long
// call stops at its next progress point. Call with the GIL held.
void checkSignals();

// A keyword's value as JSON (what a settings table checks); numpy scalars count as the
// Python numbers they hold (bind_nbv.cpp).
nlohmann::json pythonToJson(const py::object& v, const std::string& name);

// Every keyword applied to `s` through its settings table (geometry/settings_table.h): a
// name outside the table is a TypeError naming `lister` (the function that lists them), a
// value outside its row an InputError naming the keyword.
template <typename S>
void applyKeywords(S& s, const std::vector<SettingField<S>>& table, const py::kwargs& keywords, const char* who,
                   const char* lister) {
  for (const auto& [key, value] : keywords) {
    const std::string name = py::str(key);
    const SettingField<S>* f = findSetting(table, name);
    if (!f) throw py::type_error(std::string(who) + ": unknown keyword '" + name + "' (" + lister + " lists them)");
    setSetting(s, *f, pythonToJson(py::reinterpret_borrow<py::object>(value), name), SettingNaming::kKeyword);
  }
}

// A table's rows for Python: a list of {name, flag, help, default, choices}.
template <typename S>
py::list settingsList(const std::vector<SettingField<S>>& table) {
  const nlohmann::json defaults = settingsJson(S{}, table);
  py::list out;
  for (const SettingField<S>& f : table)
    out.append(py::dict(py::arg("name") = f.name, py::arg("flag") = settingFlag(f), py::arg("help") = f.help,
                        py::arg("default") = py::module_::import("json").attr("loads")(defaults.at(f.name).dump()),
                        py::arg("choices") = f.choices));
  return out;
}

}  // namespace saresgs::python
