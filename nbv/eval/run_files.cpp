#include "nbv/eval/run_files.h"

#include "geometry/scene/cameras_json.h"
#include "nbv/eval/camera_plot.h"
#include "splat/model_frame.h"
#include "splat/ply.h"

namespace saresgs {

void writeRunFiles(const ActiveRun& run, const ActiveResult& r, const Scene& scene, const std::string& out) {
  writeGaussiansPly(out + "/point_cloud.ply", gaussiansToWorld(run.trainer().gaussians(), scene.frame));
  if (const Trainer* f = run.finalFitTrainer())
    writeGaussiansPly(out + "/final_fit.ply", gaussiansToWorld(f->gaussians(), scene.frame));
  if (const Trainer* f = run.finalFitViewsTrainer())
    writeGaussiansPly(out + "/final_fit_views.ply", gaussiansToWorld(f->gaussians(), scene.frame));
  writeCamerasJson(out + "/cameras.json", scene);
  writeImage(out + "/cameras.png", plotCameras(scene, r.initial_views, r.selected_views));
}

}  // namespace saresgs
