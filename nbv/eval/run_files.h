#pragma once
// The files an active run leaves beside its results.json, written the same way by
// `saresgs active` and the Python module's ActiveRun.write.
#include <string>

#include "geometry/scene/scene.h"
#include "nbv/active_run.h"

namespace saresgs {

// Into `out` (which must exist): the loop's model (point_cloud.ply) and the final fits'
// (final_fit.ply, final_fit_views.ply, when the run made them) in world coordinates
// (splat/model_frame.h), cameras.json for splat viewers (world coordinates too) and
// cameras.png (plotCameras: the initial and chosen views). `scene` is the run's dataset.
void writeRunFiles(const ActiveRun& run, const ActiveResult& r, const Scene& scene, const std::string& out);

}  // namespace saresgs
