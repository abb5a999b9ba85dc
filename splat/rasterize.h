#pragma once
// The rasterization contract, one stateless entry point like gsplat's, with a slow
// reference implementation (splat/raster/reference_renderer.h) that the fast tiled path is
// tested against. Both follow these rules exactly:
//
//  1. Projection. Camera-frame mean p = R m + t. Culled when p.z < near_plane, or when
//     the centre lies outside the frustum widened by `guard_band` about the image
//     centre: with the image spanning [l, r] = [-cx/fx, (W-cx)/fx] in x/z (likewise
//     y/z), kept when |x/z - (l+r)/2| <= guard_band (r-l)/2 and the same for y.
//  2. Covariance. Sigma = R(q) S S^T R(q)^T, S = diag(exp(log_scale)), q normalised (a
//     zero quaternion is the identity). Sigma2D = J W Sigma W^T J^T + eps2d I with
//     W = camera R, J = [[fx/z, 0, -fx x/z^2], [0, fy/z, -fy y/z^2]]. Mean in pixels:
//     (fx x/z + cx, fy y/z + cy); pixel centres are at (i + 0.5, j + 0.5).
//  3. Opacity o = sigmoid(logit). Culled when o < 1/255 (it can never contribute).
//  4. Screen extent, a rectangle centred on the 2D mean with half sizes (hx, hy):
//       kOpacityAware: h = sqrt(2 ln(255 o) Sigma2D_xx), likewise y — the exact box of
//                      the ellipse where o G >= 1/255 (gsplat's opacity-aware rule);
//       kThreeSigma:   hx = hy = 3 sqrt(lambda_max(Sigma2D)) (3DGS).
//     Culled when the rectangle misses the image. `radius` reports max(hx, hy) in px.
//     A Gaussian touches only pixels whose centre lies inside its rectangle
//     (|u - mu_x| <= hx and |v - mu_y| <= hy).
//  5. Colour from SH of the active degree along d = normalize(m - camera centre):
//     c = sum_k sh_k Y_k(d) + 0.5, then max(c, 0) per channel.
//  6. Order: per pixel, Gaussians sorted by camera z ascending, ties by index.
//  7. Compositing, front to back with T = 1: G = exp(-0.5 d^T Sigma2D^-1 d), d = pixel
//     centre - mean; alpha = min(0.99, o G); skipped when alpha < 1/255; if
//     T (1 - alpha) < 1e-4 the pixel stops before this Gaussian; otherwise
//     C += T alpha c, D += T alpha z, T *= 1 - alpha. Finally rgb = C + T background,
//     alpha = 1 - T, depth = D / (1 - T) (0 when 1 - T < 1e-6).
//  8. A per-Gaussian mask (1 = render) excludes masked Gaussians exactly as if their
//     opacity were 0; the model is not copied.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "geometry/camera/camera.h"
#include "geometry/image/image.h"
#include "splat/gaussians.h"
#include "splat/raster/constants.h"
#include "splat/raster_execution.h"

namespace saresgs {

enum class ExtentRule { kOpacityAware, kThreeSigma };

struct RasterSettings {
  int sh_degree = 0;  // active degree, <= the model's max_sh_degree
  float near_plane = 0.01f;
  float guard_band = 1.3f;
  float eps2d = 0.3f;
  ExtentRule extent = ExtentRule::kOpacityAware;
  std::array<float, 3> background{0.0f, 0.0f, 0.0f};
  RasterExecution execution;  // threads and SIMD kernels (splat/raster_execution.h)
  // false: RenderResult::depth (0 x 0) and contributors are left empty, neither computed
  // nor written. A training step and the Fisher pass's render read neither
  // (viewLossAndGradient and addViewInformation set it), and the forward kernels'
  // per-pixel step is shorter without them; every other output, the backward state
  // included, is the same bit for bit.
  bool depth_and_contributors = true;
};

// Everything the forward pass knows that the backward pass needs (opaque to callers).
template <typename T>
struct RasterStateT;

struct RenderResult {
  ImageF rgb;                         // 3 channels
  ImageF alpha;                       // 1 channel, accumulated opacity
  ImageF depth;                       // 1 channel, expected camera-z depth (see rule 7)
  std::vector<int> contributors;      // per pixel: Gaussians composited
  std::vector<float> radii;           // per Gaussian: max(hx, hy) in px, 0 when culled
  std::vector<std::uint8_t> visible;  // per Gaussian: survived culling (1) or not (0)
  std::shared_ptr<const RasterStateT<float>> state;
};

// Renders `g` from `cam`. `mask` (one byte per Gaussian, 1 = render) selects a subset
// without copying the model; empty renders all.
RenderResult rasterize(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                       std::span<const std::uint8_t> mask = {});
// The same render into `into`, reusing its buffers (and its backward state, when no other
// RenderResult shares it): bit for bit the result above, and no heap allocation once
// `into` has held a render of at least this many Gaussians, pixels and tile pairs. A
// trainer keeps one and renders into it every step.
void rasterize(const Gaussians& g, const Camera& cam, const RasterSettings& s, std::span<const std::uint8_t> mask,
               RenderResult& into);
// Adds to `grad` the gradient of a loss whose gradient w.r.t. fwd.rgb is dL_drgb; adds
// the 2D-mean gradient (pixels, 2 per Gaussian) to *grad_mean2d when given.
void rasterizeBackward(const Gaussians& g, const Camera& cam, const RasterSettings& s, const RenderResult& fwd,
                       const ImageF& dL_drgb, Gaussians& grad, std::vector<float>* grad_mean2d = nullptr);
// Adds, per parameter, the sum over pixels of the squared per-pixel gradient of the
// rendered colour (channels summed): FisherRF's diagonal information. Rotations are
// excluded (left untouched), as in FisherRF.
void rasterizeSquaredGradients(const Gaussians& g, const Camera& cam, const RasterSettings& s, const RenderResult& fwd,
                               Gaussians& sq);

// SA-ResGS's residual supervision renders, per step, the model and a subset of its
// Gaussians (splat/train/residual.h). The subset is a mask over the same projection,
// depth order and tile lists, and its alphas are the full render's, so both renders come
// from one projection, one sort and one tile walk that evaluates each alpha once.
struct SubsetRasterState;  // what the subset's backward needs (opaque)
struct RenderPair {
  RenderResult full;    // bit for bit rasterize(g, cam, s); its state serves rasterizeBackward
  RenderResult subset;  // bit for bit rasterize(g, cam, s, mask) (images, contributors, radii,
                        // visible); state is null: its backward is rasterizeBackwardWithSubset's
  std::shared_ptr<const SubsetRasterState> subset_state;
};
// `mask` has one byte per Gaussian (1 = in the subset).
RenderPair rasterizeWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                               std::span<const std::uint8_t> mask);
// The same into `into`, reusing its buffers as rasterize(..., into) does.
void rasterizeWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                         std::span<const std::uint8_t> mask, RenderPair& into);
// Both renders' backward passes in one walk: adds to `grad` and *grad_mean2d what
// rasterizeBackward of the full render with dL_drgb_full followed by rasterizeBackward
// of rasterize(g, cam, s, mask) with dL_drgb_subset add (each branch's weight folded into
// its image), up to float rounding: each Gaussian's two projected gradients are summed
// before the chain rule instead of after. Deterministic (fixed-order sums), whatever the
// thread count.
void rasterizeBackwardWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s, const RenderPair& fwd,
                                 const ImageF& dL_drgb_full, const ImageF& dL_drgb_subset, Gaussians& grad,
                                 std::vector<float>* grad_mean2d = nullptr);

}  // namespace saresgs
