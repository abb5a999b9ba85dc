// The trainer: train on views with progress and Ctrl-C, evaluate, save and load.
#include <memory>

#include "python/src/bindings.h"
#include "splat/model_frame.h"
#include "splat/ply.h"
#include "splat/train/schedule.h"
#include "splat/train/train_settings.h"
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
  m.def(
      "train_settings", [] { return settingsList(trainSettingFields()); },
      "Every setting of a training (Trainer's keywords, `saresgs train`'s flags, results.json's \"settings\"): a "
      "list of {name, flag, help, default, choices}.");
  py::class_<Trainer>(m, "Trainer",
                      "3DGS training (3DGS's schedule, densification and Adam) on a dataset's views, from its SfM "
                      "points; optionally with SA-ResGS's residual supervision.")
      .def(py::init([](const std::shared_ptr<Scene>& scene, const py::object& background, const py::kwargs& keywords) {
             // The same table as `saresgs train`'s flags (splat/train/train_settings.h).
             TrainSettings settings;
             applyKeywords(settings, trainSettingFields(), keywords, "Trainer", "saresgs.train_settings()");
             const TrainerOptions o = trainerOptionsFrom(settings);
             const std::shared_ptr<Scene> dataset = withBackground(scene, background);
             py::gil_scoped_release nogil;
             return std::make_unique<Trainer>(*dataset, o);
           }),
           py::arg("dataset"), py::kw_only(), py::arg("background") = py::none(),
           "Trainer(dataset, *, background=None, **settings): the settings are `saresgs train`'s flags with "
           "underscores (seed, max_sh_degree, schedule_scale, max_gaussians, residual, threads, ...; "
           "saresgs.train_settings() lists them); background as load_dataset's (None: the dataset's own).")
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
