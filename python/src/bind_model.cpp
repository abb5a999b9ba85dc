// The Gaussian model, rendering, gradients, the training loss and the metrics.
#include <cmath>

#include "geometry/scene/scene.h"
#include "python/src/bindings.h"
#include "splat/gaussians.h"
#include "splat/loss.h"
#include "splat/metrics.h"
#include "splat/model_frame.h"
#include "splat/ply.h"
#include "splat/rasterize.h"

namespace saresgs::python {

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// A writable view of one of the model's arrays (no copy), kept alive by the model's
// Python object. Valid while the model keeps its size (nothing in Python resizes it).
py::array_t<float> view(py::object owner, std::vector<float>& v, std::vector<py::ssize_t> shape) {
  return py::array_t<float>(std::move(shape), v.data(), owner);
}

// Copies `a` into `dst`, which must hold n x per values; `what` names the array in errors.
void assign(std::vector<float>& dst, const py::array& a, std::size_t n, std::size_t per, const char* what,
            const char* shape_text) {
  const FloatArray f = FloatArray::ensure(a);
  if (!f || static_cast<std::size_t>(f.size()) != n * per || f.ndim() < 1 || static_cast<std::size_t>(f.shape(0)) != n)
    throw py::value_error(std::string(what) + ": expected shape " + shape_text + " with N = " + std::to_string(n));
  dst.assign(f.data(), f.data() + f.size());
}

RasterSettings settingsFor(const Gaussians& g, py::object sh_degree, const std::array<float, 3>& background,
                           int threads) {
  RasterSettings s;
  s.sh_degree = sh_degree.is_none() ? g.max_sh_degree : sh_degree.cast<int>();
  if (s.sh_degree < 0 || s.sh_degree > g.max_sh_degree)
    throw py::value_error("sh_degree " + std::to_string(s.sh_degree) + ": expected 0.." +
                          std::to_string(g.max_sh_degree) + " (the model's degree)");
  s.background = background;
  s.execution.threads = threads;
  return s;
}

void checkModel(const Gaussians& g) {
  const std::size_t n = g.size();
  if (g.means.size() != 3 * n || g.log_scales.size() != 3 * n || g.rotations.size() != 4 * n ||
      g.sh.size() != static_cast<std::size_t>(g.shCoeffs()) * 3 * n)
    throw py::value_error("Gaussians: inconsistent array sizes");
}

// The property of one of the model's arrays: a writable float32 view, (N, cols), or (N,)
// for cols 0; assigning an array of that shape copies it in.
auto arrayGetter(std::vector<float> Gaussians::*member, py::ssize_t cols) {
  return [member, cols](py::object self) {
    auto& g = self.cast<Gaussians&>();
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(g.size())};
    if (cols > 0) shape.push_back(cols);
    return view(self, g.*member, shape);
  };
}
auto arraySetter(std::vector<float> Gaussians::*member, std::size_t per, const char* what, const char* shape) {
  return [=](Gaussians& g, const py::array& a) { assign(g.*member, a, g.size(), per, what, shape); };
}

py::tuple renderTuple(RenderResult&& r) {
  return py::make_tuple(imageArray(std::move(r.rgb)), imageArray(std::move(r.depth)), imageArray(std::move(r.alpha)));
}

}  // namespace

void bindModel(py::module_& m) {
  py::class_<Gaussians>(m, "Gaussians",
                        "A 3D Gaussian model as 3DGS stores it: means (N, 3), log_scales (N, 3), rotations (N, 4) "
                        "quaternions w x y z, opacities (N,) logits, sh (N, K, 3) with K = (max_sh_degree + 1)^2. "
                        "The array properties are writable float32 views of the model (no copy); assigning an "
                        "array of the same shape copies it in.")
      .def(py::init([](const py::array& means, const py::array& log_scales, const py::array& rotations,
                       const py::array& opacities, const py::array& sh) {
             const FloatArray mf = FloatArray::ensure(means), shf = FloatArray::ensure(sh);
             if (!mf || mf.ndim() != 2 || mf.shape(1) != 3) throw py::value_error("means: expected shape (N, 3)");
             const std::size_t n = static_cast<std::size_t>(mf.shape(0));
             if (!shf || shf.ndim() != 3 || static_cast<std::size_t>(shf.shape(0)) != n || shf.shape(2) != 3)
               throw py::value_error("sh: expected shape (N, K, 3), K = 1, 4, 9 or 16");
             const int k = static_cast<int>(shf.shape(1));
             const int degree = k == 1 ? 0 : k == 4 ? 1 : k == 9 ? 2 : k == 16 ? 3 : -1;
             if (degree < 0) throw py::value_error("sh: K = " + std::to_string(k) + ", expected 1, 4, 9 or 16");
             Gaussians g;
             g.max_sh_degree = degree;
             assign(g.means, means, n, 3, "means", "(N, 3)");
             assign(g.log_scales, log_scales, n, 3, "log_scales", "(N, 3)");
             assign(g.rotations, rotations, n, 4, "rotations", "(N, 4)");
             assign(g.opacities, opacities, n, 1, "opacities", "(N,)");
             assign(g.sh, sh, n, static_cast<std::size_t>(k) * 3, "sh", "(N, K, 3)");
             return g;
           }),
           py::arg("means"), py::arg("log_scales"), py::arg("rotations"), py::arg("opacities"), py::arg("sh"))
      .def("__len__", &Gaussians::size)
      .def_readonly("max_sh_degree", &Gaussians::max_sh_degree)
      .def_property("means", arrayGetter(&Gaussians::means, 3), arraySetter(&Gaussians::means, 3, "means", "(N, 3)"))
      .def_property("log_scales", arrayGetter(&Gaussians::log_scales, 3),
                    arraySetter(&Gaussians::log_scales, 3, "log_scales", "(N, 3)"))
      .def_property("rotations", arrayGetter(&Gaussians::rotations, 4),
                    arraySetter(&Gaussians::rotations, 4, "rotations", "(N, 4)"))
      .def_property("opacities", arrayGetter(&Gaussians::opacities, 0),
                    arraySetter(&Gaussians::opacities, 1, "opacities", "(N,)"))
      .def_property(
          "sh",
          [](py::object self) {
            auto& g = self.cast<Gaussians&>();
            return view(self, g.sh, {static_cast<py::ssize_t>(g.size()), g.shCoeffs(), 3});
          },
          [](Gaussians& g, const py::array& a) {
            assign(g.sh, a, g.size(), static_cast<std::size_t>(g.shCoeffs()) * 3, "sh", "(N, K, 3)");
          })
      .def(
          "copy", [](const Gaussians& g) { return Gaussians(g); }, "a deep copy")
      .def_static(
          "read_ply",
          [](const std::string& path) {
            py::gil_scoped_release nogil;
            return readGaussiansPly(path);
          },
          py::arg("path"),
          "Reads a 3DGS .ply (as the reference implementation, SuperSplat and splat-transform write it).")
      .def(
          "write_ply",
          [](const Gaussians& g, const std::string& path) {
            checkModel(g);
            py::gil_scoped_release nogil;
            writeGaussiansPly(path, g);
          },
          py::arg("path"), "Writes the standard 3DGS .ply (atomically: a temporary name, then renamed).")
      .def(
          "to_world", [](const Gaussians& g, const Scene& d) { return gaussiansToWorld(g, d.frame); },
          py::arg("dataset"),
          "The model in world coordinates, from the dataset's internal frame (Dataset.frame_scale, frame_center), "
          "as .ply files hold it; a copy (the identity frame: unchanged).")
      .def(
          "from_world", [](const Gaussians& g, const Scene& d) { return gaussiansFromWorld(g, d.frame); },
          py::arg("dataset"), "The model in the dataset's internal frame, from world coordinates (read_ply's); a copy.")
      .def("__repr__", [](const Gaussians& g) {
        return "Gaussians(" + std::to_string(g.size()) + ", sh degree " + std::to_string(g.max_sh_degree) + ")";
      });

  m.def(
      "render",
      [](const Gaussians& g, const Camera& cam, py::object sh_degree, std::array<float, 3> background, int threads) {
        checkModel(g);
        const RasterSettings s = settingsFor(g, sh_degree, background, threads);
        py::gil_scoped_release nogil;
        RenderResult r = rasterize(g, cam, s);
        py::gil_scoped_acquire gil;
        return renderTuple(std::move(r));
      },
      py::arg("gaussians"), py::arg("camera"), py::arg("sh_degree") = py::none(),
      py::arg("background") = std::array<float, 3>{0, 0, 0}, py::arg("threads") = 0,
      "Renders the model: (rgb H x W x 3, depth H x W, alpha H x W), float32. sh_degree defaults to the model's.");

  m.def(
      "render_gradient",
      [](const Gaussians& g, const Camera& cam, const py::array& dL_drgb, py::object sh_degree,
         std::array<float, 3> background, int threads) {
        checkModel(g);
        const RasterSettings s = settingsFor(g, sh_degree, background, threads);
        const ImageF w = imageFromArray(dL_drgb, 3, "dL_drgb");
        if (w.width != cam.K.width || w.height != cam.K.height)
          throw py::value_error("dL_drgb: expected the camera's image size " + std::to_string(cam.K.height) + " x " +
                                std::to_string(cam.K.width));
        Gaussians grad = g.zerosLike();
        {
          py::gil_scoped_release nogil;
          const RenderResult r = rasterize(g, cam, s);
          rasterizeBackward(g, cam, s, r, w, grad);
        }
        return grad;
      },
      py::arg("gaussians"), py::arg("camera"), py::arg("dL_drgb"), py::arg("sh_degree") = py::none(),
      py::arg("background") = std::array<float, 3>{0, 0, 0}, py::arg("threads") = 0,
      "The gradient, with respect to every parameter of the model, of a loss whose gradient with respect to the "
      "rendered rgb is dL_drgb (H x W x 3): a Gaussians of the same shape.");

  m.def(
      "loss_and_gradient",
      [](const Gaussians& g, const Camera& cam, const py::array& target, double lambda_ssim, py::object sh_degree,
         std::array<float, 3> background, int threads) {
        checkModel(g);
        const RasterSettings s = settingsFor(g, sh_degree, background, threads);
        const ImageF t = imageFromArray(target, 3, "target");
        if (t.width != cam.K.width || t.height != cam.K.height)
          throw py::value_error("target: expected the camera's image size");
        Gaussians grad = g.zerosLike();
        double loss;
        {
          py::gil_scoped_release nogil;
          const RenderResult r = rasterize(g, cam, s);
          const LossResult l = photometricLoss(r.rgb, t, lambda_ssim, true);
          loss = l.loss;
          rasterizeBackward(g, cam, s, r, l.grad, grad);
        }
        return py::make_tuple(loss, grad);
      },
      py::arg("gaussians"), py::arg("camera"), py::arg("target"), py::arg("lambda_ssim") = 0.2,
      py::arg("sh_degree") = py::none(), py::arg("background") = std::array<float, 3>{0, 0, 0}, py::arg("threads") = 0,
      "3DGS's training loss (1 - l) L1 + l (1 - SSIM) of the render against `target` (H x W x 3 in [0, 1]) and its "
      "gradient: (loss, Gaussians).");

  m.def(
      "psnr",
      [](const py::array& a, const py::array& b) { return psnr(imageFromArray(a, 3, "a"), imageFromArray(b, 3, "b")); },
      py::arg("a"), py::arg("b"), "PSNR of two H x W x 3 images in [0, 1] (clamped), as 3DGS and FisherRF compute it.");
  m.def(
      "ssim",
      [](const py::array& a, const py::array& b) { return ssim(imageFromArray(a, 3, "a"), imageFromArray(b, 3, "b")); },
      py::arg("a"), py::arg("b"), "SSIM (11 x 11 Gaussian window, sigma 1.5) of two H x W x 3 images in [0, 1].");
}

}  // namespace saresgs::python
