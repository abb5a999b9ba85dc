// saresgs scene: writes a ground-truth synthetic dataset (COLMAP model, images, depth; or a
// NeRF-synthetic folder with --format blender).
#include <iostream>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/progress.h"
#include "geometry/scene/manifest.h"
#include "geometry/synth/assets.h"
#include "geometry/synth/write_dataset.h"

namespace saresgs::apps {

namespace {

struct SceneArgs {
  SyntheticOptions scene;
  WriteDatasetOptions write;
  std::string out;
  bool no_points = false;
};

int runScene(SceneArgs& a) {
  if (a.no_points) a.write.sfm = "none";
  for (auto& m : a.scene.meshes) m = resolveAsset(m);
  for (auto& t : a.scene.textures) t = resolveAsset(t);
  std::cerr << "building " << a.scene.layout << " scene (seed " << a.scene.seed << ")\n";
  const SyntheticScene scene = makeSyntheticScene(a.scene);
  Progress progress;
  a.write.progress = [&](const std::string& stage, int done, int total) { progress.update(stage, done, total); };
  a.write.simulated.seed = a.scene.seed;
  const WriteDatasetReport r = writeSyntheticDataset(scene, a.out, a.write);
  std::cout << "wrote " << a.out << " (" << a.write.format << "): layout " << a.scene.layout << ", " << r.views
            << " views (" << scene.train.size() << " train, " << scene.test.size() << " test), " << a.scene.width << "x"
            << a.scene.height << "\n"
            << "  render: " << r.render_seconds << " s total, median " << r.median_view_ms << " ms per view at "
            << std::max(4, a.write.render.samples_per_pixel) << " spp\n"
            << "  sparse points (" << a.write.sfm << "): " << r.points << ", mean track " << r.mean_track_length
            << ", reprojection error median " << r.median_reprojection_error << " px (mean "
            << r.mean_reprojection_error << " px with outliers), " << r.sfm_seconds << " s\n"
            << "  contact sheet: " << a.out << "/contact_sheet.png\n";
  return 0;
}

}  // namespace

void addSceneCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<SceneArgs>();
  CLI::App* sub = app.add_subcommand("scene", "Write a ground-truth synthetic dataset");
  sub->add_option("--layout", args->scene.layout,
                  "object | room360 | unbalanced | tworooms (real meshes, two rooms and a door) | corridor (three "
                  "rooms in a row, a walk of uneven density)")
      ->check(CLI::IsMember({"object", "room360", "unbalanced", "tworooms", "corridor"}))
      ->capture_default_str();
  sub->add_option("--out", args->out, "Output folder")->required();
  addRanged(sub, "--width", args->scene.width, "Image width", 16, 8192);
  addRanged(sub, "--height", args->scene.height, "Image height", 16, 8192);
  sub->add_option("--seed", args->scene.seed, "Random seed")->check(wholeNumberAtLeast(0))->capture_default_str();
  sub->add_option("--views", args->scene.num_views, "Number of views (0: the layout's default)")
      ->check(CLI::Range(0, kMaxSyntheticViews));
  sub->add_option("--mesh", args->scene.meshes, "Mesh files (OFF/PLY/OBJ) or cgal:NAME; default procedural");
  sub->add_option("--texture", args->scene.textures, "Photographs (PNG/JPEG) or opencv:FILE; default procedural");
  sub->add_option("--up", args->scene.up_axis, "Up axis of the mesh files")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  sub->add_option("--projection", args->scene.projection, "Photograph mapping")
      ->check(CLI::IsMember({"triplanar", "spherical"}))
      ->capture_default_str();
  addRanged(sub, "--spp", args->write.render.samples_per_pixel, "Samples per pixel (>= 4)", 4, 4096);
  sub->add_flag("--specular", args->write.render.specular, "Add a mild specular highlight");
  CLI::Option* sfm = sub->add_option("--sfm", args->write.sfm, "Sparse points: simulated | colmap | none")
                         ->check(CLI::IsMember({"simulated", "colmap", "none"}))
                         ->capture_default_str();
  sub->add_flag("--no-points", args->no_points, "No sparse points (the same as --sfm none)")->excludes(sfm);
  sub->add_option("--format", args->write.format,
                  "colmap (sparse/0, images/) | blender (NeRF-synthetic: transforms_*.json, RGBA train/ and test/, "
                  "points3d.ply)")
      ->check(CLI::IsMember({"colmap", "blender"}))
      ->capture_default_str();
  sub->callback([&action, args] { action = [args] { return runScene(*args); }; });
}

}  // namespace saresgs::apps
