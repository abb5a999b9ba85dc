#pragma once
// Surface textures for the synthetic scenes. A texture maps a point and a unit normal,
// both in the object's own (local) frame, to a linear RGB albedo in [0,1]. Procedural
// textures are solid (defined in 3D, so they need no UV layout); photographs are
// mapped triplanar (three axis projections blended by the normal) or spherical
// (longitude/latitude around the local origin) and sampled bilinearly.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>

#include "geometry/image/image.h"

namespace saresgs::synth {

class Texture {
 public:
  virtual ~Texture() = default;
  virtual Eigen::Vector3f albedo(const Eigen::Vector3f& p, const Eigen::Vector3f& n) const = 0;
  // A short description for the manifest, e.g. "procedural:marble".
  virtual std::string describe() const = 0;
};

using Color = Eigen::Vector3f;
// A colour from 8-bit sRGB-looking components (just divided by 255).
Color rgb(int r, int g, int b);

// 3D checkerboard with cells of size `cell`, lightly mottled by noise.
std::shared_ptr<Texture> makeChecker(float cell, Color a, Color b, std::uint64_t seed);
// Bands perpendicular to `axis` with period `period`, cycling through three colours,
// edges wobbled by noise (wallpaper, painted stripes).
std::shared_ptr<Texture> makeStripes(const Eigen::Vector3f& axis, float period, Color a, Color b, Color c,
                                     std::uint64_t seed);
// Veined marble: a sine along `axis` perturbed by turbulence.
std::shared_ptr<Texture> makeMarble(float scale, Color base, Color vein, std::uint64_t seed);
// Wood rings around the line through `centre` along `axis`, with grain noise. A centre
// outside the object makes long grain lines on surfaces parallel to the axis.
std::shared_ptr<Texture> makeWood(const Eigen::Vector3f& axis, const Eigen::Vector3f& centre, float ring_spacing,
                                  Color light, Color dark, std::uint64_t seed);
// Wooden planks `width` wide and `length` long, projected along the dominant normal
// axis; they run along the first in-plane coordinate (x on floors, y or x on walls).
std::shared_ptr<Texture> makePlanks(float width, float length, Color light, Color dark, std::uint64_t seed);
// Running-bond bricks of size w x h with mortar joints, projected along the dominant
// normal axis; each brick gets its own shade.
std::shared_ptr<Texture> makeBricks(float w, float h, float mortar, Color brick, Color joint, std::uint64_t seed);
// Square tiles with grout, each tile one of two colours and mottled.
std::shared_ptr<Texture> makeTiles(float size, float grout, Color a, Color b, Color joint, std::uint64_t seed);
// Granite/plaster: a base colour with multi-scale speckles.
std::shared_ptr<Texture> makeSpeckle(float scale, Color base, Color spot, std::uint64_t seed);
// Dots of `radius` around one random point per lattice cell of size `spacing` (3D), over
// a mottled background.
std::shared_ptr<Texture> makeDots(float spacing, float radius, Color background, Color dot, std::uint64_t seed);

enum class Projection { Triplanar, Spherical };
// Parses "triplanar" or "spherical"; throws InputError naming the option otherwise.
Projection parseProjection(const std::string& name);
// A photograph (RGB, converted to float [0,1]); `scale` = local units per image width
// for triplanar mapping. `source` names the file for the manifest.
std::shared_ptr<Texture> makeImageTexture(std::shared_ptr<const ImageF> image, Projection projection, float scale,
                                          const std::string& source);
// Bilinear sample at continuous texel coordinates (x, y) (texel centres at +0.5),
// wrapping around in x and, if `wrap_y`, in y (clamped otherwise).
Color sampleBilinear(const ImageF& img, float x, float y, bool wrap_y);

}  // namespace saresgs::synth
