#pragma once
// Writes a synthetic scene as a dataset that any COLMAP-reading tool accepts:
//   OUT/images/NAME.png        supersampled renders
//   OUT/depth/STEM.pfm         ground-truth depth (z along the camera axis, 0 = miss)
//   OUT/sparse/0/*.txt         COLMAP text model: cameras, images with 2D points, points3D
//   OUT/manifest.json          layout, seed, meshes, textures, split, SfM statistics
//   OUT/contact_sheet.png      thumbnails of the views (test views framed)
// or, with format "blender", as a NeRF-synthetic folder:
//   OUT/transforms_train.json, transforms_test.json   camera_angle_x and, per frame,
//                              file_path ("./train/0000", no extension) and the
//                              camera-to-world transform_matrix in OpenGL axes
//   OUT/train/NAME.png, test/NAME.png   RGBA: object layouts have true alpha (the fraction
//                              of a pixel's samples that hit the object, colour
//                              un-premultiplied); rooms are opaque
//   OUT/points3d.ply           the sparse points (3DGS's file), unless sfm is "none"
//   OUT/depth, manifest.json (no split: the transforms hold it), contact_sheet.png
// The folder is assembled under a temporary name and renamed into place at the end.
#include <functional>
#include <string>

#include "geometry/synth/simulated_sfm.h"
#include "geometry/synth/synthetic_scene.h"

namespace saresgs {

struct WriteDatasetOptions {
  RenderOptions render;
  std::string format = "colmap";  // colmap | blender
  std::string sfm = "simulated";  // simulated | colmap (runs the COLMAP binary; colmap format only) | none
  SimulatedSfmOptions simulated;
  std::function<void(const std::string& stage, int done, int total)> progress;
};

struct WriteDatasetReport {
  int views = 0;
  std::size_t points = 0;
  double mean_track_length = 0;
  double mean_reprojection_error = 0;    // px, as stored in points3D (outliers included)
  double median_reprojection_error = 0;  // px; robust to the simulated outliers
  double render_seconds = 0;
  double median_view_ms = 0;  // colour render of one view
  double sfm_seconds = 0;
};

WriteDatasetReport writeSyntheticDataset(const SyntheticScene& scene, const std::string& out,
                                         const WriteDatasetOptions& opts = {});

// The cameras and images of `scene` as a COLMAP model without points (image id i + 1
// is scene.cameras[i]; one camera record per distinct intrinsics).
ColmapModel colmapModelOf(const SyntheticScene& scene);

}  // namespace saresgs
