#pragma once
// A model between a scene's world frame and the internal frame it is trained in
// (geometry/scene/scene_frame.h): means move and scale with the frame, log-scales shift by
// log(scale); rotations, opacities and colours do not change. Files (.ply) hold world
// coordinates, so writers map with gaussiansToWorld and readers with gaussiansFromWorld.
// The identity frame returns the model unchanged, bit for bit.
#include "geometry/scene/scene_frame.h"
#include "splat/gaussians.h"

namespace saresgs {

Gaussians gaussiansToWorld(const Gaussians& internal, const SceneFrame& frame);
Gaussians gaussiansFromWorld(const Gaussians& world, const SceneFrame& frame);

}  // namespace saresgs
