#include "geometry/lifting/extrapolation.h"

namespace saresgs {

Camera extrapolatedCamera(const Camera& cam, double sx, double sy, double back) {
  // The rows of R are the camera axes in world coordinates; t = -R c.
  const Eigen::Vector3d c =
      cam.center() + sx * cam.R.row(0).transpose() + sy * cam.R.row(1).transpose() - back * cam.R.row(2).transpose();
  Camera e = cam;
  e.t = -cam.R * c;
  return e;
}

std::vector<Camera> extrapolatedCameras(const Camera& cam, double extent, const ExtrapolationOptions& opts) {
  const double dx = opts.dx_fraction * extent;
  const double dy = opts.dy_fraction * extent;
  const double dz = opts.dz_fraction * extent;
  std::vector<Camera> out{extrapolatedCamera(cam, dx, dy, dz)};
  if (!opts.all_combinations) return out;
  for (int sy = -1; sy <= 1; ++sy)
    for (int sx = -1; sx <= 1; ++sx) {
      if ((sx == 0 && sy == 0) || (sx == 1 && sy == 1)) continue;
      out.push_back(extrapolatedCamera(cam, sx * dx, sy * dy, dz));
    }
  return out;
}

}  // namespace saresgs
