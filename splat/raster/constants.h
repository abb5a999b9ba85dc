#pragma once
// The rasterizer contract's constants (splat/rasterize.h states the rules they belong to),
// in a header with no includes and no code, so that the SIMD kernels compiled with other
// instruction sets (splat/raster/raster_kernels_impl.h) use these very values instead of
// restating them.

namespace saresgs {

// Rule 7: a contribution counts where alpha = o G >= kMinAlpha; alpha is clamped to
// kMaxAlpha; a pixel stops once its transmittance would fall below kMinTransmittance.
inline constexpr float kMinAlpha = 1.0f / 255.0f;
inline constexpr float kMaxAlpha = 0.99f;
inline constexpr float kMinTransmittance = 1e-4f;
// The square tile the image is binned and composited by, in pixels.
inline constexpr int kTileSize = 16;
// SH degree-0 basis constant: colour = SH_C0 * dc + 0.5 at degree 0.
inline constexpr double kShC0 = 0.28209479177387814;

}  // namespace saresgs
