#pragma once
// The float tile kernels of the fast rasterizer (internal). They are compiled from
// splat/raster/raster_kernels_impl.h (and the backward, pair and projection parts beside
// it) once per instruction set, each compilation choosing its options with a KernelIsa
// traits type: four lanes for the baseline target (raster_kernels_base.cpp), eight with
// AVX2 and FMA (raster_kernels_avx2.cpp, its own compile flags), and AVX2's eight lanes and
// arithmetic on AVX-512VL's 32 registers for the walks that gain from them
// (raster_kernels_avx512.cpp, bit-identical to AVX2's). Each compilation's functions have
// internal linkage and reach the rasterizer only through its KernelSet below, so no
// function compiled for AVX2 or AVX-512 can be picked by the linker for the baseline
// path. No implicit FMA contraction in any; the AVX2 build fuses the multiply-adds
// written as fma() and the baseline rounds them twice, so the baseline and AVX2 paths
// agree to float rounding (FloatPath.KernelSetsAgree), while each is bit-identical
// across runs and thread counts.
#include <cstddef>
#include <cstdint>

#include "splat/raster/projected.h"

namespace saresgs {

// One Gaussian's data gathered per tile, in the tile's order. The chord terms bound, per
// pixel row at offset dy from the mean, the columns where o G >= 1/255 can hold: centred
// on mx + chord_slope dy with half width sqrt(chord_k0 - chord_k1 dy^2), widened so the
// float per-pixel test never passes outside it (tileData in raster_stages.h); the kernels
// use them for Gaussians wider than 32 pixels. They only shorten the kernels' loops; the
// per-pixel test decides.
// The pixel spans (image columns px0..px1, rows py0..py1, inclusive; empty when
// px0 > px1) hold every pixel whose centre can pass the float test |i + 0.5 - mean| <=
// half: the exact bound widened by 1e-6 relative and 1e-3 px, computed once per Gaussian
// (pixelSpan in raster_stages.h) so that a tile's loops start from integer clipping.
// The kernels bound a Gaussian's block rows by its chords when its pixel span
// (px1 - px0 + 1) is wider than this (forEachBlock); tileData computes the chords only for
// such Gaussians and for those whose tiles tileMeets tests.
inline constexpr int kChordMinSpan = 32;

template <typename T>
struct TileGaussian {
  T mx, my, a, b, c, o, hx, hy, depth;
  T col[3];
  T chord_slope, chord_k0, chord_k1;
  std::int32_t px0 = 1, px1 = 0, py0 = 1, py1 = 0;
};

namespace raster_kernels {

// Where the forward kernel writes a tile's pixels (whole-image arrays, row stride W).
// depth and contributors are both given or both null: null, the kernel neither computes
// nor writes them (a training step's render), and every other value is the same.
struct ForwardOut {
  int W;
  float* rgb;
  float* alpha;
  float* depth;
  int* contributors;
  float* final_T;
  std::uint32_t* n_walked;
};

// What the backward kernel reads per pixel (whole-image arrays, row stride W).
struct BackwardIn {
  int W;
  const float* final_T;
  const std::uint32_t* n_walked;
  const float* dL_drgb;  // 3 per pixel
};

// Pixels [x0, x1) x [y0, y1) composited front to back over q[0, nq) (rule 7).
using CompositeFn = void (*)(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                             const ForwardOut& out);
// The back-to-front walk of a tile: for each tile entry jj its 9 gradient sums
// (opacity, mean2d 2, conic 3, colour 3) go to slots[jj * 9], `slots` being the tile's
// first entry's slot: slots follow the tile lists, so a tile's are one run of memory
// (every entry's slot is written, zeros where no pixel reaches it).
using BackwardFn = void (*)(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                            const BackwardIn& in, float* slots);

// FisherRF's squared-gradient pass (splat/fisher.h) works on the per-pixel gradient of
// C_r + C_g + C_b, which is linear in a contribution's 2D inputs: dL/dalpha times G (e,
// where alpha = o G is not clamped, else 0) and the colour weight alpha T (wc). The
// squared parameter gradient, summed over pixels, is a quadratic form in those inputs
// whose pixel dependence is polynomial in the offsets (dx, dy) from the 2D mean (degree
// <= 2 per input: the mean terms are linear, the conic terms quadratic). So a tile needs,
// per Gaussian, only the sums below; the per-Gaussian Jacobian is applied once to them
// (fisher_pass.cpp) instead of at every pixel. E_ij = sum e^2 dx^i dy^j, F_ij = sum e wc
// dx^i dy^j, W = sum wc^2.
enum FisherMoment {
  kE00,
  kE20,
  kE11,
  kE02,
  kE30,
  kE21,
  kE12,
  kE03,
  kE40,
  kE31,
  kE22,
  kE13,
  kE04,
  kF10,
  kF01,
  kF20,
  kF11,
  kF02,
  kW,
  kFisherSlot  // floats per pair slot
};

// What the Fisher kernel reads per pixel (whole-image arrays, row stride W).
struct FisherIn {
  int W;
  const float* final_T;
  const std::uint32_t* n_walked;
};

// The back-to-front walk of a tile for the objective C_r + C_g + C_b: for each tile
// entry jj its kFisherSlot moments go to slots[jj * kFisherSlot], `slots` being the
// tile's first entry's slot (every entry's slot is written, zeros where no pixel reaches
// it).
using FisherFn = void (*)(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                          const FisherIn& in, float* slots);

// What the projection kernels (splat/raster/project_kernels_impl.h) read: the model's
// arrays (GaussiansT<float>'s storage), the camera in float (projection::CameraT<float>)
// and the settings, converted as project() converts them.
struct ProjectIn {
  const float* means;       // 3 per Gaussian
  const float* log_scales;  // 3
  const float* rotations;   // 4 (w, x, y, z)
  const float* opacities;   // 1 (logit)
  const float* sh;          // sh_stride per Gaussian
  int sh_stride;            // 3 x the model's SH coefficients
  int sh_degree;            // active degree, 0-3
  float R[3][3], t[3], center[3];
  float fx, fy, cx, cy, width, height;
  float gx_mid, gx_half, gy_mid, gy_half;
  float near_plane, eps2d;
};

// Rules 1-5 (projection::project<float> with the opacity-aware extent) for Gaussians
// [begin, end), KernelSet::lanes at a time, into out[i] for each i: bit for bit what
// project() returns for every visible Gaussian, and visible = false where it culls (the
// other fields of a culled Gaussian are unspecified there as here).
using ProjectFn = void (*)(const ProjectIn& in, std::size_t begin, std::size_t end, projection::Projected<float>* out);
// Where the projection's backward kernels add a Gaussian's parameter gradients
// (GaussiansT<float>'s storage; sh with ProjectIn::sh_stride per Gaussian).
struct ProjectGradOut {
  float* means;
  float* log_scales;
  float* rotations;
  float* opacities;
  float* sh;
};

// projection::projectBackward<float> with every parameter asked for, for the Gaussians
// idx[0, count) (distinct), given their projections (proj[idx[j]]) and the gradients of
// their projected quantities (dP[j]): adds to `out` bit for bit what projectBackward adds.
using ProjectBackwardFn = void (*)(const ProjectIn& in, const std::uint32_t* idx, int count,
                                   const projection::Projected<float>* proj, const projection::ProjectedGrad<float>* dP,
                                   const ProjectGradOut& out);
// Where the Fisher chain adds a Gaussian's squared gradients (GaussiansT<float>'s storage).
struct FisherGradOut {
  float* means;
  float* log_scales;
  float* opacities;
  float* sh;
};

// The Fisher pass's per-Gaussian stage (fisher_pass.cpp's squaredGradientsFloat): for the
// Gaussians idx[0, count) (distinct), given their projections (proj[idx[j]]) and their
// tile moments summed in double (moments[j * kFisherSlot + m]), backwardFrame and
// projectJacobian in float, the quadratic forms in double, and the squared gradients of
// the means, log-scales, opacity logit and SH added to `out`, bit for bit the scalar stage.
using FisherChainFn = void (*)(const ProjectIn& in, const std::uint32_t* idx, int count,
                               const projection::Projected<float>* proj, const double* moments,
                               const FisherGradOut& out);
// A full render and the render of a subset of its Gaussians in one walk of the full tile
// lists (splat/raster/raster_kernels_pair_impl.h): in_subset[j] (per tile entry) says
// whether entry j is in the subset. Each render is bit-identical to the single-render
// kernel's, run on that render's own tile lists, except that the subset's n_walked counts
// full-list entries. The backward writes the sum of the two branches' sums at the full
// render's pair slots (every entry's slot, zeros where neither branch walks it): equal to
// the two single backward passes' slots added, up to float rounding. `slots` is the tile's
// first entry's slot, as for BackwardFn.
using CompositePairFn = void (*)(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0,
                                 int x1, int y1, const float bg[3], const ForwardOut& full, const ForwardOut& subset);
using BackwardPairFn = void (*)(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0,
                                int x1, int y1, const float bg[3], const BackwardIn& full, const BackwardIn& subset,
                                float* slots);

// compositeTile's per-lane arithmetic for n rounds of two blocks in registers (no memory
// traffic): the floor a tile kernel could reach (raster_kernels_impl.h). Returns a checksum.
using CompositeFloorFn = float (*)(long n);

// The options one compilation of the kernels is built with (splat/raster/raster_kernels_impl.h
// reads them as KernelIsa): lanes per vector (4 or 8), AVX2 + FMA intrinsics (eight lanes,
// x86-64 only), and the Fisher walk summing its 19 moments as it goes (for a target with
// 32 vector registers; with 16 they spill and the three-pass form is faster).
template <int Lanes, bool Fma, bool FisherOnePass>
struct KernelOptions {
  static constexpr int kLanes = Lanes;
  static constexpr bool kFma = Fma;
  static constexpr bool kFisherOnePass = FisherOnePass;
};
// The three compilations the rasterizer chooses from at run time.
struct BaselineIsa : KernelOptions<4, false, false> {  // raster_kernels_base.cpp
  static constexpr const char* kName = "baseline";
};
struct Avx2Isa : KernelOptions<8, true, false> {  // raster_kernels_avx2.cpp
  static constexpr const char* kName = "avx2";
};
struct Avx512Isa : KernelOptions<8, true, true> {  // raster_kernels_avx512.cpp
  static constexpr const char* kName = "avx512";
};

// One compilation of the kernels: everything the rasterizer calls for one instruction set.
struct KernelSet {
  const char* name;  // "baseline", "avx2", "avx512"
  int lanes;         // pixels (or Gaussians) per vector
  CompositeFn composite;
  BackwardFn backward;
  FisherFn fisher;
  CompositePairFn composite_pair;
  BackwardPairFn backward_pair;
  ProjectFn project;
  ProjectBackwardFn project_backward;
  FisherChainFn fisher_chain;
  CompositeFloorFn composite_floor;
};

// The kernel set of the compilation with options Isa, as data that compilation defines
// (constant-initialized, so that reading it runs no instruction of another instruction
// set); null where this build has no such compilation (not x86-64, or not GCC/Clang).
template <class Isa>
struct CompiledKernels {
  static const KernelSet* const set;
};
template <>
const KernelSet* const CompiledKernels<BaselineIsa>::set;
template <>
const KernelSet* const CompiledKernels<Avx2Isa>::set;
// Avx512Isa's set holds only the walks that gain from AVX-512VL's 32 registers (backward,
// fisher, composite_pair, backward_pair; the other members null), bit-identical to AVX2's:
// the rasterizer's avx512 set is the AVX2 set with these (raster_execution::kernelSet).
template <>
const KernelSet* const CompiledKernels<Avx512Isa>::set;

}  // namespace raster_kernels
}  // namespace saresgs
