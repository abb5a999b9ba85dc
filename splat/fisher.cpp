#include "splat/fisher.h"

#include <stdexcept>

#include "splat/fisher_detail.h"

namespace saresgs {

void addViewInformation(const Gaussians& g, const Camera& cam, const RasterSettings& s, Gaussians& H) {
  addViewInformationT(g, cam, s, H);
}

std::vector<float> gaussianGeometryVariance(const Gaussians& H, double lambda) {
  std::vector<float> out(H.size());
  for (std::size_t i = 0; i < H.size(); ++i) {
    double v = 0;
    for (int k = 0; k < 3; ++k) {
      v += 1.0 / (static_cast<double>(H.means[3 * i + k]) + lambda);
      v += 1.0 / (static_cast<double>(H.log_scales[3 * i + k]) + lambda);
    }
    out[i] = static_cast<float>(v);
  }
  return out;
}

Gaussians withScalarColor(const Gaussians& g, const std::vector<float>& value) {
  if (value.size() != g.size()) throw std::invalid_argument("withScalarColor: one value per Gaussian expected");
  Gaussians out;
  out.max_sh_degree = 0;
  out.means = g.means;
  out.log_scales = g.log_scales;
  out.rotations = g.rotations;
  out.opacities = g.opacities;
  out.sh.resize(3 * g.size());
  for (std::size_t i = 0; i < g.size(); ++i)
    for (int c = 0; c < 3; ++c) out.sh[3 * i + c] = static_cast<float>((value[i] - 0.5) / kShC0);
  return out;
}

}  // namespace saresgs
