#include "splat/gaussians.h"

namespace saresgs {

void Gaussians::resize(std::size_t n) {
  forEachArray([n](std::vector<float>& a, std::size_t per) { a.resize(n * per, 0.0f); });
}

Gaussians Gaussians::zerosLike() const {
  Gaussians z;
  z.max_sh_degree = max_sh_degree;
  z.resize(size());
  return z;
}

}  // namespace saresgs
