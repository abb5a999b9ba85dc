#pragma once
// The frame saresgs computes in. A dataset's world frame is whatever its producer chose:
// COLMAP's arbitrary scale, millimetres or kilometres, georeferenced coordinates 1e5..1e6
// from the origin. The Gaussians' means are single precision (1e6 from the origin a float
// resolves 6 cm) and a few defaults are absolute (the renderer's near plane, Fisher's
// lambda against the means' information), so every loaded scene is moved into a frame of
// its own:
//
//   x_internal = (x_world - center) / scale
//
// `scale` is the power of ten at or below the scene's extent (sceneExtent of the train
// cameras), so the internal extent lies in [1, 10): rooms and objects of metres, the range
// every default was made for. `center` is the train cameras' mean centre rounded to a
// multiple of 10 x scale, so a scene within a few extents of the origin keeps center 0.
// Round numbers are chosen on purpose: a dataset already in that range is not touched at
// all (its numbers stay bit for bit those of earlier versions), and a change of unit
// (x 1e3, x 1e-3) or a round offset (what COLMAP's model_transformer and georeferencing
// with a round origin produce) is undone up to the last bit of a double, so such a frame
// trains to the same numbers. Any other frame is brought within a factor of 10 of scale
// and one extent of the origin.
//
// Files hold world coordinates: models are written with gaussiansToWorld (splat/ply.h's
// callers) and read back with gaussiansFromWorld; results.json records the frame.
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/camera/camera.h"

namespace saresgs {

struct SceneFrame {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double scale = 1.0;

  bool identity() const { return scale == 1.0 && center.isZero(0.0); }
  Eigen::Vector3d toInternal(const Eigen::Vector3d& x_world) const { return (x_world - center) / scale; }
  Eigen::Vector3d toWorld(const Eigen::Vector3d& x) const { return x * scale + center; }
  // The same camera (same image) with its pose in the internal frame: camera space is
  // scaled with the world, so x_cam / scale = R x_internal + (t + R center) / scale.
  Camera toInternal(const Camera& world) const;
  Camera toWorld(const Camera& internal) const;
  bool operator==(const SceneFrame&) const = default;
};

// The frame for cameras whose extent (sceneExtent) and mean centre are given, as described
// above. A zero or non-finite extent (one camera, or none) gives the identity.
SceneFrame chooseSceneFrame(double extent, const Eigen::Vector3d& mean_center);

// {"center": [x, y, z], "scale": s}, and back (InputError naming `file` and `field` when it
// is not that, or the centre is not finite or the scale not positive and finite).
nlohmann::json toJson(const SceneFrame& f);
SceneFrame sceneFrameFromJson(const nlohmann::json& j, const std::string& file, const std::string& field);

}  // namespace saresgs
