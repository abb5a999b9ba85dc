#pragma once
// Image quality metrics as FisherRF and 3DGS define them (docs/DESIGN.md): PSNR on images
// clamped to [0,1]; SSIM with an 11x11 Gaussian window, sigma 1.5, C1 = 0.01^2,
// C2 = 0.03^2, computed at every pixel with zero padding outside the image ("same"
// size, as 3DGS's reference implementation does) and averaged over pixels and channels.
#include "geometry/image/image.h"

namespace saresgs {

double psnr(const ImageF& a, const ImageF& b);
double ssim(const ImageF& a, const ImageF& b);

}  // namespace saresgs
