// View selection: FisherRF and FVS scores, the SA-Point prefilter's coverage, and the
// active loop, steppable and with selectors written in Python.
#include <memory>
#include <optional>

#include "geometry/error.h"
#include "nbv/active_run.h"
#include "nbv/coverage_prefilter.h"
#include "nbv/prefilter_options.h"
#include "nbv/eval/run_files.h"
#include "report/run_page.h"
#include "nbv/eval/coverage_report.h"
#include "nbv/method.h"
#include "nbv/active_settings.h"
#include "nbv/preset.h"
#include "splat/thread_limit.h"
#include "nbv/run_report.h"
#include "nbv/selectors.h"
#include "geometry/io/atomic_file.h"
#include "python/src/bindings.h"
#include "splat/raster_execution.h"

namespace saresgs::python {

namespace {

py::object jsonToPython(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

}  // namespace

nlohmann::json pythonToJson(const py::object& v, const std::string& name) {
  py::object plain = v;
  if (py::hasattr(v, "item") && py::hasattr(v, "dtype")) plain = v.attr("item")();
  try {
    return nlohmann::json::parse(py::module_::import("json").attr("dumps")(plain).cast<std::string>());
  } catch (const py::error_already_set&) {
    throw py::type_error(name + ": expected a number, text, bool or None, got " +
                         py::str(py::type::of(v).attr("__name__")).cast<std::string>());
  }
}

namespace {

// ActiveRun's docstring: its own arguments, then every setting of the table.
const std::string& activeRunInitDoc() {
  static const std::string doc = [] {
    std::string d =
        "ActiveRun(dataset, *, selector=None, checkpoint='', background=None, **settings). `selector` (a callable "
        "taking a SelectionContext and returning a candidate, or (candidate, scores)) replaces the method's "
        "selection (method 'custom'); `checkpoint` names a checkpoint file written after every added view and resumed "
        "when present; background as load_dataset's (None: the dataset's own). The settings are `saresgs active`'s "
        "flags with underscores (the preset's value where not given):\n";
    for (const auto& f : activeSettingFields()) d += "  " + f.name + ": " + f.help + "\n";
    return d;
  }();
  return doc;
}

void checkTrainViews(const Scene& s, const std::vector<int>& views, const char* what) {
  for (int v : views)
    if (std::find(s.train.begin(), s.train.end(), v) == s.train.end())
      throw py::value_error(std::string(what) + ": view " + std::to_string(v) + " is not a train view of the dataset");
}

FisherCriterion parseCriterion(const std::string& c) {
  if (c == "trace") return FisherCriterion::kTrace;
  if (c == "logdet") return FisherCriterion::kLogDet;
  throw py::value_error("criterion '" + c + "': expected trace or logdet");
}

// What a Python selector receives: a view of the loop's state, valid during its call only
// (the references it holds belong to the loop).
struct PySelectionContext {
  const SelectionContext* ctx = nullptr;
  const SelectionContext& get() const {
    if (!ctx)
      throw std::runtime_error("SelectionContext: used after the selector returned (it is valid during the call only)");
    return *ctx;
  }
};

// The Python ActiveRun: the loop, the dataset it was given and the Python callables. The
// loop's callbacks hold only a pointer to this object, so no Python object is copied or
// released without the GIL.
struct PyActiveRun {
  std::shared_ptr<Scene> dataset;
  std::string preset;
  ActiveSettings settings;
  ActiveOptions opt;
  py::object selector = py::none(), progress = py::none();
  std::unique_ptr<ActiveRun> run;
  std::optional<ActiveResult> result;

  // threads=N holds all of a call's TBB work at N, as --threads does for the CLI.
  std::unique_ptr<tbb::global_control> threadLimit() const {
    return limitThreads(opt.trainer.raster.execution.threads);
  }

  void onProgress(const ActiveProgress& p) {
    py::gil_scoped_acquire gil;
    checkSignals();
    if (progress.is_none()) return;
    progress(py::dict(py::arg("phase") = toString(p.phase), py::arg("phase_done") = p.phase_done,
                      py::arg("phase_total") = p.phase_total, py::arg("views") = p.views,
                      py::arg("max_views") = p.max_views, py::arg("iteration") = p.iteration,
                      py::arg("total_iterations") = p.total_iterations, py::arg("loss") = p.loss,
                      py::arg("psnr") = p.psnr, py::arg("gaussians") = p.gaussians));
  }

  int select(const SelectionContext& ctx, SelectionLog& log) {
    py::gil_scoped_acquire gil;
    // Owned by Python (a selector may keep it); its pointer to the loop is cleared on return.
    py::object pyctx = py::cast(PySelectionContext{&ctx});
    PySelectionContext& held_ctx = pyctx.cast<PySelectionContext&>();
    py::object r;
    try {
      r = selector(pyctx);
    } catch (...) {
      held_ctx.ctx = nullptr;
      throw;
    }
    held_ctx.ctx = nullptr;
    // An int, or (int, scores per candidate).
    if (py::isinstance<py::tuple>(r)) {
      const py::tuple t = r.cast<py::tuple>();
      if (t.size() != 2) throw py::value_error("selector: expected a view index or (view, scores)");
      log.scores = t[1].cast<std::vector<double>>();
      return t[0].cast<int>();
    }
    return r.cast<int>();
  }

  // Installs the callbacks that point here (before every call into the loop).
  void wire() {
    run->setProgress([this](const ActiveProgress& p) { onProgress(p); });
  }

  py::object report(const std::string& dataset_path) const {
    if (!result) throw std::runtime_error("ActiveRun: no result yet (run() or finish() first)");
    const RunReport r = makeRunReport(
        *dataset, opt, *result,
        {dataset_path, preset, {}, run->trainer().gaussians().size(), rasterThreadCount(opt.trainer.raster.execution)});
    nlohmann::json j = toJson(r);
    j["settings"] = activeSettingsJson(settings);
    return jsonToPython(j);
  }
};

}  // namespace

void bindNbv(py::module_& m) {
  m.def("methods", &methodNames, "The built-in view-selection methods (`saresgs active --method`), plus custom.");
  m.def(
      "active_settings", [] { return settingsList(activeSettingFields()); },
      "Every setting of an active run (ActiveRun's keywords, `saresgs active`'s flags, results.json's "
      "\"settings\"): a list of {name, flag, help, default (None: the preset's), choices}.");

  m.def(
      "fisher_scores",
      [](const Gaussians& g, const std::shared_ptr<Scene>& scene, const std::vector<int>& held,
         const std::vector<int>& candidates, py::object sh_degree, double lambda, const std::string& criterion,
         int threads) {
        RasterSettings s;
        s.sh_degree = sh_degree.is_none() ? g.max_sh_degree : sh_degree.cast<int>();
        if (scene->background) s.background = *scene->background;
        s.execution.threads = threads;
        checkTrainViews(*scene, held, "held");
        checkTrainViews(*scene, candidates, "candidates");
        const FisherCriterion c = parseCriterion(criterion);
        py::gil_scoped_release nogil;
        return fisherScores(g, s, *scene, held, candidates, lambda, {}, c);
      },
      py::arg("gaussians"), py::arg("dataset"), py::arg("held"), py::arg("candidates"),
      py::arg("sh_degree") = py::none(), py::arg("fisher_lambda") = 1e-6, py::arg("criterion") = "trace",
      py::arg("threads") = 0,
      "FisherRF's expected information gain of each candidate view given the held views: trace "
      "(sum H_v / (H_train + lambda)) or logdet (sum log(1 + H_v / (H_train + lambda))).");

  m.def(
      "fvs_scores",
      [](const std::shared_ptr<Scene>& scene, const std::vector<int>& held, const std::vector<int>& candidates,
         const std::string& metric) {
        checkTrainViews(*scene, held, "held");
        checkTrainViews(*scene, candidates, "candidates");
        if (metric != "euclidean" && metric != "great-circle")
          throw py::value_error("metric: expected euclidean or great-circle");
        return fvsScores(*scene, held, candidates,
                         metric == "euclidean" ? ViewDistance::kEuclidean : ViewDistance::kGreatCircle);
      },
      py::arg("dataset"), py::arg("held"), py::arg("candidates"), py::arg("metric") = "euclidean",
      "Farthest view sampling: each candidate camera's distance to the nearest held one.");

  m.def(
      "coverage",
      [](const std::shared_ptr<Scene>& scene, const std::vector<int>& views, std::optional<Gaussians> model,
         const std::string& set, const std::string& encoding, const std::string& score, const std::string& lifting,
         std::optional<std::string> scene_type, double keep) {
        checkTrainViews(*scene, views, "views");
        // as `saresgs coverage` parses them (scene_type None: the base's grid stands)
        PrefilterConfig c =
            parsePrefilterFlags({set, encoding, score, lifting, scene_type.value_or("")}, PrefilterConfig{}, "");
        c.keep_fraction = keep;
        py::gil_scoped_release nogil;
        const CoverageRenderers renderers =
            coverageRenderers(*scene, scene->source, model ? &*model : nullptr, "given as model=", "model=");
        const CoverageAnalysis a = analyzeCoverage(*scene, views, c, renderers.render, renderers.depth);
        py::gil_scoped_acquire gil;
        py::dict d;
        d["encoding"] = encodingName(c.scoring);
        d["prefilter_regime"] = jsonToPython(toJson(a.prefilter->regime()));
        d["scene_voxels"] = a.scene_voxels;
        d["observed_voxels"] = a.observed_voxels;
        d["observed_fraction"] = a.observed_fraction;
        std::vector<int> cand, rank;
        std::vector<double> sc;
        std::vector<bool> kept;
        for (const CandidateCoverage& k : a.candidates) {
          cand.push_back(k.view);
          sc.push_back(k.score);
          rank.push_back(k.rank);
          kept.push_back(k.kept);
        }
        d["candidates"] = cand;
        d["scores"] = sc;
        d["ranks"] = rank;
        d["kept"] = kept;
        d["top"] = a.top;
        d["sa_points"] = jsonToPython(a.lifting.toJson());
        return d;
      },
      py::arg("dataset"), py::arg("views"), py::arg("model") = py::none(), py::arg("set") = "frustum",
      py::arg("encoding") = "hash:auto", py::arg("score") = "xor", py::arg("lifting") = "flow",
      py::arg("scene_type") = py::none(), py::arg("keep") = 0.2,
      "The SA-Point prefilter as `saresgs coverage` runs it: SA-Points lifted from `views` (rendered by `model`, or "
      "the ground truth of a `saresgs scene` folder), the voxels they observe, and every other train view's score "
      "(set frustum | visible, encoding hash:auto | hash:K | exact, score xor | new, lifting flow | depth | oracle, "
      "scene_type indoor | outdoor | None).");

  py::class_<PySelectionContext>(
      m, "SelectionContext",
      "What a Python selector sees when the loop asks for the next view (valid during the call only).")
      .def_property_readonly(
          "held", [](const PySelectionContext& c) { return c.get().held; }, "the views held, in order")
      .def_property_readonly(
          "candidates", [](const PySelectionContext& c) { return c.get().candidates; },
          "the train views not held: the selector returns one of them")
      .def_property_readonly("dataset",
                             [](const PySelectionContext& c) { return std::make_shared<Scene>(c.get().scene); })
      .def_property_readonly(
          "gaussians", [](const PySelectionContext& c) { return Gaussians(c.get().trainer.gaussians()); },
          "a copy of the model trained on the held views")
      .def(
          "render",
          [](const PySelectionContext& c, int view) {
            const SelectionContext& x = c.get();
            if (view < 0 || view >= static_cast<int>(x.scene.views.size()))
              throw py::index_error("view outside the dataset");
            RenderResult r;
            {
              py::gil_scoped_release nogil;
              r = x.trainer.render(x.scene.views[static_cast<std::size_t>(view)].camera);
            }
            return py::make_tuple(imageArray(std::move(r.rgb)), imageArray(std::move(r.depth)),
                                  imageArray(std::move(r.alpha)));
          },
          py::arg("view"), "the model's render of a view: (rgb, depth, alpha)")
      .def(
          "fisher_scores",
          [](const PySelectionContext& c, py::object candidates, const std::string& criterion) {
            const SelectionContext& x = c.get();
            const std::vector<int> cand = candidates.is_none() ? x.candidates : candidates.cast<std::vector<int>>();
            checkTrainViews(x.scene, cand, "candidates");
            const FisherCriterion cr = parseCriterion(criterion);
            py::gil_scoped_release nogil;
            return fisherScores(x.trainer.gaussians(), x.trainer.rasterSettings(), x.scene, x.held, cand,
                                x.fisher_lambda, {}, cr);
          },
          py::arg("candidates") = py::none(), py::arg("criterion") = "trace",
          "FisherRF's scores of the candidates (default: all) on the current model, as the fisher method computes them")
      .def(
          "fvs_scores",
          [](const PySelectionContext& c, py::object candidates) {
            const SelectionContext& x = c.get();
            const std::vector<int> cand = candidates.is_none() ? x.candidates : candidates.cast<std::vector<int>>();
            checkTrainViews(x.scene, cand, "candidates");
            return fvsScores(x.scene, x.held, cand);
          },
          py::arg("candidates") = py::none(), "farthest view sampling's distances, as the fvs method computes them")
      .def(
          "random_choice",
          [](const PySelectionContext& c, py::object candidates) {
            const SelectionContext& x = c.get();
            const std::vector<int> cand = candidates.is_none() ? x.candidates : candidates.cast<std::vector<int>>();
            return selectRandom(cand, x.rng);
          },
          py::arg("candidates") = py::none(),
          "a uniformly random candidate drawn from the run's own generator (the one the random method draws from)");

  py::class_<PyActiveRun>(
      m, "ActiveRun",
      "One active run (`saresgs active`): hold initial views, then per phase train and add the "
      "selector's view, until max_views; then the final evaluation and final fit. run() does it all; "
      "train_phase(), next_view(), add_view() and finish() step through it. `selector` (a callable "
      "taking a SelectionContext and returning a candidate, or (candidate, scores)) replaces the "
      "method's selection: the run is then method 'custom'.")
      .def(py::init([](const std::shared_ptr<Scene>& dataset, py::object selector, const std::string& checkpoint,
                       const py::object& background, const py::kwargs& keywords) {
             auto r = std::make_unique<PyActiveRun>();
             r->dataset = withBackground(dataset, background);
             // The same table of settings as `saresgs active`'s flags, turned into options by
             // the same function (nbv/active_settings.h).
             ActiveSettings& settings = r->settings;
             applyKeywords(settings, activeSettingFields(), keywords, "ActiveRun", "saresgs.active_settings()");
             if (!selector.is_none()) settings.method = "custom";
             r->preset = settings.preset;
             ActiveOptions& o = r->opt;
             o = activeOptionsFrom(settings, dataset->source, SettingNaming::kKeyword);
             if (!selector.is_none()) {
               if (!PyCallable_Check(selector.ptr()))
                 throw py::type_error("selector: expected a callable(SelectionContext)");
               r->selector = selector;
               PyActiveRun* self = r.get();
               o.custom_selector = [self](const SelectionContext& c, SelectionLog& log) {
                 return self->select(c, log);
               };
             }
             py::gil_scoped_release nogil;
             r->run = std::make_unique<ActiveRun>(*r->dataset, o, checkpoint);
             return r;
           }),
           py::arg("dataset"), py::kw_only(), py::arg("selector") = py::none(), py::arg("checkpoint") = "",
           py::arg("background") = py::none(), activeRunInitDoc().c_str())
      .def_property_readonly("method", [](const PyActiveRun& r) { return std::string(toString(r.opt.method)); })
      .def_property_readonly(
          "held", [](const PyActiveRun& r) { return r.run->held(); }, "the views held, in order")
      .def_property_readonly(
          "finished", [](const PyActiveRun& r) { return r.run->finished(); },
          "the last phase is trained (finish() is next)")
      .def(
          "run",
          [](PyActiveRun& r, py::object progress) {
            r.progress = progress;
            py::gil_scoped_release nogil;
            const auto limit = r.threadLimit();
            r.result = r.run->run([&r](const ActiveProgress& p) { r.onProgress(p); });
            py::gil_scoped_acquire gil;
            return r.report(r.dataset->source);
          },
          py::arg("progress") = py::none(),
          "The whole run; returns the report results.json holds (a dict). progress(dict) is called as the CLI's "
          "progress line is; Ctrl-C stops the run (KeyboardInterrupt) at its next progress point.")
      .def(
          "train_phase",
          [](PyActiveRun& r, py::object progress) {
            r.progress = progress;
            r.wire();
            py::gil_scoped_release nogil;
            const auto limit = r.threadLimit();
            r.run->trainPhase();
          },
          py::arg("progress") = py::none(), "Trains the phase of the views held now (nothing if trained already).")
      .def(
          "next_view",
          [](PyActiveRun& r, py::object progress) {
            r.progress = progress;
            r.wire();
            SelectionLog log;
            int v;
            {
              py::gil_scoped_release nogil;
              const auto limit = r.threadLimit();
              v = r.run->nextView(&log);
            }
            py::dict d;
            d["view"] = v;
            d["candidates"] = log.candidates;
            d["scores"] = log.scores;
            return d;
          },
          py::arg("progress") = py::none(),
          "The method's next view after this phase (trained first when needed): {view, candidates, scores}.")
      .def(
          "add_view",
          [](PyActiveRun& r, int v) {
            r.wire();
            py::gil_scoped_release nogil;
            const auto limit = r.threadLimit();
            r.run->addView(v);
          },
          py::arg("view"), "Holds `view` next (the method's choice or any train view not held).")
      .def(
          "finish",
          [](PyActiveRun& r, py::object progress) {
            r.progress = progress;
            r.wire();
            {
              py::gil_scoped_release nogil;
              const auto limit = r.threadLimit();
              r.result = r.run->finish();
            }
            return r.report(r.dataset->source);
          },
          py::arg("progress") = py::none(), "The final evaluation and final fit; returns the report (a dict).")
      .def_property_readonly(
          "gaussians", [](const PyActiveRun& r) { return Gaussians(r.run->trainer().gaussians()); },
          "a copy of the loop's current model")
      .def_property_readonly("final_fit_gaussians",
                             [](const PyActiveRun& r) -> py::object {
                               const Trainer* t = r.run->finalFitTrainer();
                               return t ? py::cast(Gaussians(t->gaussians())) : py::none();
                             })
      .def(
          "write",
          [](const PyActiveRun& r, const std::string& out, bool html) -> py::object {
            py::object report = r.report(r.dataset->source);
            const std::string text =
                py::module_::import("json").attr("dumps")(report, py::arg("indent") = 2).cast<std::string>();
            py::gil_scoped_release nogil;
            std::filesystem::create_directories(out);
            writeRunFiles(*r.run, *r.result, *r.dataset, out);
            writeFileAtomic(out + "/results.json", text + "\n");
            if (!html) {
              py::gil_scoped_acquire gil;
              return py::none();
            }
            const RunPageResult page = writeRunPage(out, r.dataset.get(), RunPageOptions{});
            py::gil_scoped_acquire gil;
            py::dict d;
            d["path"] = page.path;
            d["bytes"] = page.bytes;
            d["viewer"] = page.viewer;
            d["missing"] = page.missing;
            return d;
          },
          py::arg("out"), py::arg("report") = true,
          "Writes results.json, the .ply files, cameras.json and cameras.png into `out`, as `saresgs active` does, and "
          "with `report` the run's page, report.html (saresgs report); returns {path, bytes, viewer, missing} of the "
          "page (missing: what it could not show, and why), or None without it.");
}

}  // namespace saresgs::python
