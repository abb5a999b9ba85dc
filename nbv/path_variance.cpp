#include "nbv/path_variance.h"

namespace saresgs {

namespace {

// Adds b to a, array by array (rotations left out, as the scores leave them out).
void addInformation(Gaussians& a, const Gaussians& b) {
  auto add = [](std::vector<float>& x, const std::vector<float>& y) {
    for (std::size_t k = 0; k < x.size(); ++k) x[k] += y[k];
  };
  add(a.means, b.means);
  add(a.log_scales, b.log_scales);
  add(a.opacities, b.opacities);
  add(a.sh, b.sh);
}

std::size_t informationBytes(const Gaussians& g) {
  return (g.means.size() + g.log_scales.size() + g.opacities.size() + g.sh.size()) * sizeof(float);
}

}  // namespace

std::vector<double> pathVarianceScores(const Gaussians& g, const RasterSettings& s, const Scene& scene,
                                       const std::vector<int>& chosen, const std::vector<int>& candidates,
                                       const PathVarianceOptions& opt, const std::function<void(int, int)>& tick) {
  Gaussians H = g.zerosLike();
  for (int v : chosen) addViewInformation(g, scene.views.at(v).camera, s, H);
  Gaussians W = H;
  const int total = static_cast<int>(candidates.size());
  // The first pass: each candidate's information, summed into W and kept while it fits.
  const std::size_t per = std::max<std::size_t>(1, informationBytes(g));
  const std::size_t keep = std::min(candidates.size(), opt.keep_bytes / per);
  std::vector<Gaussians> kept(keep);
  Gaussians Hc = g.zerosLike();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (tick) tick(static_cast<int>(i) / 2, total);
    clearInformation(Hc);
    addViewInformation(g, scene.views.at(candidates[i]).camera, s, Hc);
    addInformation(W, Hc);
    if (i < keep) {
      kept[i] = Hc;
      kept[i].rotations = {};
    }
  }
  const GroupDamping l = relativeDamping(H, opt.kappa, opt.lambda);
  std::vector<double> out;
  out.reserve(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (tick) tick(total / 2 + static_cast<int>(i) / 2, total);
    if (i < keep) {
      out.push_back(pathVarianceScore(kept[i], H, W, l));
      kept[i] = Gaussians{};  // memory back as it goes
    } else {
      clearInformation(Hc);
      addViewInformation(g, scene.views.at(candidates[i]).camera, s, Hc);
      out.push_back(pathVarianceScore(Hc, H, W, l));
    }
  }
  if (tick) tick(total, total);
  return out;
}

}  // namespace saresgs
