#pragma once
// SA-Points (paper Sec. 3.1): 3D points lifted from one training view. For each
// extrapolated camera of the view, the image source renders the extrapolated image, a
// lifting module finds correspondences between the real image and that render, they are
// thinned to a stride grid and triangulated, and points that fail the checks of
// triangulation.h are dropped. The result is a plain vector of points plus a report.
//
// Modules (each a LiftingModule value; a user can write another):
//   flow     dense correspondences from OpenCV DIS optical flow with a forward-backward
//            consistency check (our stand-in for MASt3R; no network needed), thinned to
//            the stride and refined on the epipolar lines of the known pair
//            (epipolar_refine.h): plain DIS drifts along those lines under the zoom of the
//            backward step and on repetitive texture, which no reprojection test can see;
//   matches  correspondences read from files (correspondence.h), e.g. MASt3R run elsewhere
//            on the real image and the extrapolated render;
//   depth    an oracle for tests and ablations: pixels of the real view are unprojected with
//            a supplied depth map and projected into the extrapolated camera, which gives
//            correspondences that are exact up to the depth map. They go through the same
//            stride, triangulation and checks as the others, so this module measures the
//            pipeline's own loss (border, near-parallel rays near the epipole) and not
//            a shortcut.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "geometry/camera/camera.h"
#include "geometry/image/image.h"
#include "geometry/lifting/correspondence.h"
#include "geometry/lifting/epipolar_refine.h"
#include "geometry/lifting/extrapolation.h"
#include "geometry/lifting/triangulation.h"

namespace saresgs {

// Image source: the scene seen by a camera, float RGB in [0,1], the camera's image size.
// The trainer supplies its rasterizer; tests use SyntheticScene::render.
using ViewRenderer = std::function<ImageF(const Camera&)>;
// Depth source for the oracle module: z depth along the camera axis (1 channel, the
// camera's image size); 0 or non-finite where unknown. Tests use SyntheticScene::renderDepth.
using DepthRenderer = std::function<ImageF(const Camera&)>;

// What a module sees for one extrapolated view.
struct LiftingPair {
  const Camera& real;
  const ImageF& real_image;
  const Camera& extrapolated;
  const ImageF& extrapolated_image;  // empty when the module does not need renders
  int view = -1;                     // the caller's index of the real view
  int extrapolation = 0;             // index into extrapolatedCameras(real, ...)
  int stride = 1;                    // the pipeline's stride: a module may thin to it early (subsampleByStride
                                     // is idempotent, so the pipeline's own thinning then changes nothing)
};

struct CorrespondenceSet {
  std::vector<Correspondence> matches;  // x0 in the real view, x1 in the extrapolated view
  std::size_t candidates = 0;           // what the module started from, before its own checks
                                        // (pixels for flow and depth, lines read for matches)
};

struct LiftingModule {
  std::string name;
  bool needs_render = true;  // false: the renderer is not called (render time stays 0)
  std::function<CorrespondenceSet(const LiftingPair&)> correspond;
};

// ----------------------------------------------------------------------------- flow
enum class FlowPreset { kUltrafast, kFast, kMedium };
// "ultrafast" | "fast" | "medium"; throws InputError("flow preset", ...) otherwise.
FlowPreset parseFlowPreset(const std::string& name);
const char* flowPresetName(FlowPreset p);

struct FlowOptions {
  // Medium preset: 0.09 px on a simple motion; on SA-Points pairs plain DIS is far
  // worse (third_party_notes/opencv.md), which the refinement below repairs.
  FlowPreset preset = FlowPreset::kMedium;
  // A pixel p is kept when |F(p) + B(p + F(p))| < this, F the flow real -> extrapolated,
  // B the flow back (bilinear): occluded and mismatched pixels fail it.
  double max_fb_error_px = 1.0;
  // Finest pyramid level DIS computes on (0 = full resolution); -1 keeps the preset's
  // (medium: 1, fast and ultrafast: 2), which halves or quarters small images.
  int finest_scale = -1;
  // Refine each flow match on its epipolar line (epipolar_refine.h); the cameras of a
  // lifting pair are known, so only depth is searched. Off: plain DIS (an ablation).
  bool epipolar_refine = true;
  EpipolarRefineOptions refine;
};

// Flow from image0 to image1 (same size, RGB or grey float in [0,1], converted to 8-bit
// luma for DIS) at every pixel centre that passes the check and whose target lies inside
// image1's pixel-centre range. candidates = width * height.
CorrespondenceSet flowCorrespondences(const ImageF& image0, const ImageF& image1, const FlowOptions& opts = {});
// The module: flowCorrespondences, thinned to the pair's stride, then (by default)
// refineOnEpipolarLines with the pair's cameras.
LiftingModule flowModule(const FlowOptions& opts = {});

// -------------------------------------------------------------------------- matches
// `path_pattern` names the file of one pair: every "{view}" is replaced by the view index
// and every "{extrapolation}" by the extrapolated view's index, e.g.
// "matches/{view}_{extrapolation}.csv". Files are read when the pair is lifted.
std::string matchesPath(const std::string& path_pattern, int view, int extrapolation);
LiftingModule matchesModule(std::string path_pattern, const MatchesFileOptions& opts = {});

// ---------------------------------------------------------------------------- depth
// Every pixel centre of `real` with a positive finite depth, unprojected and projected into
// `other` (dropped when behind it). candidates = width * height.
CorrespondenceSet depthCorrespondences(const Camera& real, const ImageF& depth, const Camera& other);
LiftingModule depthModule(DepthRenderer depth_of);

// --------------------------------------------------------------------------- lifting
struct LiftingOptions {
  ExtrapolationOptions extrapolation;
  int stride = 5;                    // paper: 5 px in x and y (subsampleByStride)
  double max_reprojection_px = 1.0;  // paper: tau = 1 px, mean over both views
  double min_ray_angle_deg = 2.0;    // see TriangulationOptions
  // Near plane as a fraction of the extent: 0.002 * 4.5 ~= 0.01, the 3DGS znear on a
  // Mip-NeRF 360 scene.
  double near_fraction = 0.002;
  double border_px = 1.0;  // see TriangulationOptions
};

// One SA-Point: a plain value, ready for an occupancy grid.
struct SAPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3f color = Eigen::Vector3f::Zero();  // real image at x0 (nearest pixel)
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // x0: where the real view saw it
  float reprojection_px = 0;                        // mean two-view error
};

struct LiftingReport {
  std::string module;
  int view = -1;
  int extrapolated_views = 0;
  std::size_t candidates = 0;       // summed over the extrapolated views
  std::size_t correspondences = 0;  // returned by the module
  std::size_t subsampled = 0;       // after the stride
  std::size_t kept = 0;
  std::array<std::size_t, kRejectionCount> rejected{};  // indexed by Rejection; [0] unused
  double median_reprojection_px = 0;                    // over the kept points; 0 when none
  double seconds_render = 0;                            // wall-clock per stage, summed over extrapolated views
  double seconds_correspondence = 0;
  double seconds_triangulation = 0;

  std::size_t rejectedBy(Rejection r) const { return rejected[static_cast<int>(r)]; }
  void add(const LiftingReport& other);  // sums counts and times (median: not combined)
  nlohmann::json toJson() const;
};

struct LiftingResult {
  std::vector<SAPoint> points;  // in the order extrapolated view, then stride cell
  LiftingReport report;
};

// Lifts one training view. `real_image` is its image (RGB in [0,1], the camera's size);
// `extent` the scene scale that the options' fractions refer to; `view` is passed to the
// module (matches file names) and the report. Throws InputError on a non-positive extent,
// a bad stride, a missing renderer or images of the wrong size.
LiftingResult liftView(const Camera& real, const ImageF& real_image, double extent, const ViewRenderer& render,
                       const LiftingModule& module, const LiftingOptions& opts = {}, int view = -1);

std::vector<Eigen::Vector3d> positions(std::span<const SAPoint> points);

}  // namespace saresgs
