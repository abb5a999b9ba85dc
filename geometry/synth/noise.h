#pragma once
// Hashes and smooth 3D noise for procedural shapes and textures. Pure functions of
// their arguments, so everything built from them is deterministic.
#include <Eigen/Core>
#include <cstdint>

namespace saresgs::synth {

// A 64-bit mixing function (SplitMix64 finaliser).
std::uint64_t mix64(std::uint64_t x);
// Hash of up to four integers.
std::uint64_t hashInts(std::int64_t a, std::int64_t b = 0, std::int64_t c = 0, std::uint64_t seed = 0);
// The top 24 bits of a hash as a float in [0, 1).
float unitFloat(std::uint64_t h);

// Gradient (Perlin-style) noise, roughly in [-1, 1], zero at lattice points.
float gradientNoise(const Eigen::Vector3f& p, std::uint64_t seed);
// Fractal sum of `octaves` noise layers (frequency x2, amplitude x0.5 per octave),
// normalised to roughly [-1, 1].
float fbm(const Eigen::Vector3f& p, int octaves, std::uint64_t seed);
// Like fbm but sums |noise|: ridged, in roughly [0, 1].
float turbulence(const Eigen::Vector3f& p, int octaves, std::uint64_t seed);

}  // namespace saresgs::synth
