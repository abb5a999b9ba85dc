#pragma once
// The fast SSIM (+ L1) kernel shared by the training loss (splat/loss.h) and the
// evaluation metric (splat/metrics.h); the algorithm and its accuracy are described in
// ssim.cpp.
//
// Images are interleaved (row-major, `channels` values per pixel) float arrays of
// w * h * channels values. SSIM is the 3DGS definition: 11x11 Gaussian window (sigma 1.5,
// the outer product of the normalised 1-D window), zero padding ("same" size),
// C1 = 0.01^2, C2 = 0.03^2, no clamping.
//
// Arithmetic is float, vectorised, parallel over fixed row blocks; every row is computed
// by the same operations whichever thread runs it and the per-row sums are reduced in row
// order in double, so the results do not depend on the thread count or scheduling.
#include <cstddef>

namespace saresgs {

struct SsimL1Sums {
  double one_minus_ssim = 0;  // sum over pixels and channels of (1 - S)
  double abs_diff = 0;        // sum over pixels and channels of |x - y| (in double)
};

// When `grad` is not null it receives, for every value i,
//   grad[i] = l1_scale * sign(x[i] - y[i]) + ssim_scale * d(sum_p S_p) / dx[i]
// (sign(0) = 0); with ssim_scale == 0 the SSIM backward is skipped. The sums are the
// same, bit for bit, whether or not the gradient is asked for.
SsimL1Sums ssimL1(const float* x, const float* y, int w, int h, int channels, float* grad, double l1_scale,
                  double ssim_scale);

// The loops run as the widest vector code the CPU has: AVX-512 (16 floats per
// instruction), AVX2 (8) or baseline SSE2 (4), never with FMA; all give bit-identical
// results. For tests and timing:
enum class SsimIsa { kBaseline = 0, kAvx2 = 1, kAvx512 = 2 };
SsimIsa ssimBestIsa();              // the widest this CPU (and build) offers
void ssimLimitIsa(SsimIsa widest);  // caps the loops at `widest` (kAvx512: no cap)

}  // namespace saresgs
