// The trainer: train on views with progress and Ctrl-C, evaluate, save and load.
#include <memory>

#include "python/src/bindings.h"
#include "splat/model_frame.h"
#include "splat/ply.h"
#include "splat/train/schedule.h"
#include "splat/thread_limit.h"
#include "splat/train/trainer.h"

namespace saresgs::python {

namespace {

py::dict progressDict(const TrainProgress& p) {
  return py::dict(py::arg("iteration") = p.iteration, py::arg("done") = p.done, py::arg("total") = p.total,
                  py::arg("loss") = p.loss, py::arg("loss_ema") = p.loss_ema, py::arg("gaussians") = p.gaussians);
}

py::dict evaluationDict(const Evaluation& e) {
  py::dict d;
  d["psnr"] = e.psnr;
  d["ssim"] = e.ssim;
  py::list views;
  for (const ViewMetrics& v : e.views) {
    py::dict x;
    x["view"] = v.view;
    x["psnr"] = v.psnr;
    x["ssim"] = v.ssim;
    views.append(x);
  }
  d["views"] = views;
  return d;
}

void checkViews(const Scene& s, const std::vector<int>& views) {
  for (int v : views)
    if (v < 0 || v >= static_cast<int>(s.views.size()))
      throw py::index_error("view " + std::to_string(v) + " outside 0.." + std::to_string(s.views.size()));
}

}  // namespace

void bindTrain(py::module_& m) {
  py::class_<Trainer>(m, "Trainer",
                      "3DGS training (3DGS's schedule, densification and Adam) on a dataset's views, from its SfM "
                      "points; optionally with SA-ResGS's residual supervision.")
      .def(py::init([](const std::shared_ptr<Scene>& scene, std::uint64_t seed, double schedule_scale,
                       std::size_t max_gaussians, int max_sh_degree, bool residual, int threads,
                       const py::object& background) {
             TrainerOptions o;
             o.seed = seed;
             o.max_sh_degree = max_sh_degree;
             o.densify.max_gaussians = max_gaussians;
             o.residual.enabled = residual;
             o.raster.execution.threads = threads;
             if (schedule_scale != 1.0) o = scaledSchedule(o, schedule_scale);
             const std::shared_ptr<Scene> dataset = withBackground(scene, background);
             py::gil_scoped_release nogil;
             return std::make_unique<Trainer>(*dataset, o);
           }),
           py::arg("dataset"), py::arg("seed") = 0, py::arg("schedule_scale") = 1.0, py::arg("max_gaussians") = 0,
           py::arg("max_sh_degree") = 3, py::arg("residual") = false, py::arg("threads") = 0,
           py::arg("background") = py::none(),
           "As `saresgs train`: schedule_scale scales the densification, opacity-reset and SH schedules (the quick "
           "preset's is 0.25); max_gaussians caps the model (0: none); threads 0 uses every core; background as "
           "load_dataset's (None: the dataset's own).")
      .def(
          "train",
          [](Trainer& t, const std::vector<int>& views, int iterations, py::object callback, int every) {
            checkViews(t.scene(), views);
            if (iterations < 0) throw py::value_error("iterations: expected >= 0");
            if (every < 1) throw py::value_error("every: expected >= 1");
            py::gil_scoped_release nogil;
            const auto limit = limitThreads(t.rasterSettings().execution.threads);  // threads=N: all TBB work
            // Each iteration takes the GIL back briefly: Ctrl-C stops the call (KeyboardInterrupt)
            // after a whole iteration, the model left as trained so far.
            t.train(views, iterations, [&](const TrainProgress& p) {
              py::gil_scoped_acquire gil;
              checkSignals();
              if (!callback.is_none() && (p.done % every == 0 || p.done == p.total)) callback(progressDict(p));
            });
          },
          py::arg("views"), py::arg("iterations"), py::arg("callback") = py::none(), py::arg("every") = 1,
          "Trains `iterations` iterations on `views` (indices into the dataset); callback(progress) is called every "
          "`every` iterations with a dict (iteration, done, total, loss, loss_ema, gaussians).")
      .def(
          "step",
          [](Trainer& t, int view) {
            checkViews(t.scene(), {view});
            py::gil_scoped_release nogil;
            const auto limit = limitThreads(t.rasterSettings().execution.threads);
            return t.step(view);
          },
          py::arg("view"), "One iteration on one view; returns its loss.")
      .def(
          "evaluate",
          [](const Trainer& t, py::object views) {
            std::vector<int> v = views.is_none() ? t.scene().test : views.cast<std::vector<int>>();
            checkViews(t.scene(), v);
            Evaluation e;
            {
              py::gil_scoped_release nogil;
              e = t.evaluate(v);
            }
            return evaluationDict(e);
          },
          py::arg("views") = py::none(),
          "PSNR and SSIM on `views` (default: the test views): {psnr, ssim, views: [{view, psnr, ssim}]}.")
      .def(
          "render",
          [](const Trainer& t, const Camera& cam) {
            RenderResult r;
            {
              py::gil_scoped_release nogil;
              r = t.render(cam);
            }
            return py::make_tuple(imageArray(std::move(r.rgb)), imageArray(std::move(r.depth)),
                                  imageArray(std::move(r.alpha)));
          },
          py::arg("camera"), "Renders the current model at its active SH degree: (rgb, depth, alpha).")
      .def_property(
          "gaussians", [](const Trainer& t) { return Gaussians(t.gaussians()); },
          [](Trainer& t, const Gaussians& g) {
            if (g.max_sh_degree != t.gaussians().max_sh_degree)
              throw py::value_error("gaussians: SH degree " + std::to_string(g.max_sh_degree) + ", the trainer's is " +
                                    std::to_string(t.gaussians().max_sh_degree));
            t.mutableGaussians() = g;
          },
          "a copy of the current model, in the dataset's internal frame; assigning a model (e.g. "
          "Gaussians.read_ply(p).from_world(dataset)) continues training from it "
          "(the optimiser's moments restart when the count changes)")
      .def_property_readonly("iteration", &Trainer::iteration)
      .def_property_readonly("active_sh_degree", &Trainer::activeShDegree)
      .def("reset", &Trainer::reset, "back to the initial model and optimiser (the random generator continues)")
      .def(
          "save_ply",
          [](const Trainer& t, const std::string& path) {
            py::gil_scoped_release nogil;
            writeGaussiansPly(path, gaussiansToWorld(t.gaussians(), t.scene().frame));
          },
          py::arg("path"))
      .def(
          "save_checkpoint",
          [](const Trainer& t, const std::string& path) {
            py::gil_scoped_release nogil;
            t.saveCheckpoint(path);
          },
          py::arg("path"), "model, optimiser and schedules, for a bit-identical resume")
      .def(
          "load_checkpoint",
          [](Trainer& t, const std::string& path) {
            py::gil_scoped_release nogil;
            t.loadCheckpoint(path);
          },
          py::arg("path"));
}

}  // namespace saresgs::python
