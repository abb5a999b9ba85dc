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
SsimL1Sums ssimL1(const float* x, const float* y, int w, int h, int channels, float* grad,
                  double l1_scale, double ssim_scale);

// The loops run as AVX2 code (8 floats per instruction, no FMA) where the CPU has it,
// otherwise as baseline SSE2; both give bit-identical results. For tests and timing:
bool ssimAvx2Available();
void ssimAllowAvx2(bool allow);  // false: baseline loops even where AVX2 is available

}  // namespace saresgs
