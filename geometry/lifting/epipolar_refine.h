#pragma once
// Guided refinement of correspondences on their epipolar lines. When the two cameras are
// known (as they are for a training view and its extrapolated view), the true match of x0
// lies on a known line in image 1; only its position along the line (the depth) is
// unknown. Optical flow is a 2D search that knows nothing of this: on repetitive texture
// and under the zoom of a backward step it drifts along the line, which the reprojection
// test cannot see. This step keeps a flow match only when it lies near the line, then
// searches the line around it for the best patch match:
//   - parameter: inverse depth rho along the ray of x0 (rho > 0: in front of camera 0);
//   - patch: (2r+1)^2 pixels around x0, each mapped to image 1 at the same depth (a
//     fronto-parallel patch in camera 0), which models the scale change of a backward
//     step exactly for fronto-parallel surfaces;
//   - score: zero-mean normalised cross-correlation (ZNCC) of luma, invariant to the
//     gain and offset differences between a real photograph and a render;
//   - sub-step position from a parabola through the best score and its two neighbours.
// Only the position along the line changes: x1 keeps its distance from the line, so the
// reprojection test of the triangulation still measures how epipolar-consistent the flow
// was (snapping onto the line would make every reprojection error zero).
// A match is dropped when it is too far from its line, its patch is textureless, the best
// score is at the end of the search range (the flow was off by more than the range), or
// the best score is below min_zncc.
#include <span>
#include <vector>

#include "geometry/camera/camera.h"
#include "geometry/image/image.h"
#include "geometry/lifting/correspondence.h"

namespace saresgs {

struct EpipolarRefineOptions {
  // The initial x1 must be this close to x0's epipolar line. Only a guard against refining
  // junk: the paper's 1 px reprojection test decides later (it sees the same distance).
  double max_epipolar_px = 3.0;
  double search_px = 3.0;  // half-length of the search along the line, pixels
  double step_px = 0.25;   // search step along the line, pixels
  int patch_radius = 3;    // 7x7 patches
  double min_zncc = 0.9;
  double min_patch_std = 0.01;  // luma standard deviation of the patch around x0 (in [0,1])
};

// Returns the refined correspondences that pass (x0 unchanged, x1 moved along the line),
// in input order. Images are RGB (or grey) float in [0,1] of the cameras' sizes.
// TBB-parallel with one slot per input, so the result does not depend on the threads.
std::vector<Correspondence> refineOnEpipolarLines(const Camera& cam0, const ImageF& image0, const Camera& cam1,
                                                  const ImageF& image1, std::span<const Correspondence> matches,
                                                  const EpipolarRefineOptions& opts = {});

}  // namespace saresgs
