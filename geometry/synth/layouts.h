#pragma once
// The camera layouts of the synthetic scenes and the objects placed in each
// (internal to geometry/synth; the public entry point is makeSyntheticScene).
//   object     one object (procedural: three parts, a bumpy marble blob, a striped ring around
//              it and a dotted ball on top;
//              or the first mesh file) at the origin, radius 1; 100 train + 50 test
//              cameras at distance 4 on the upper hemisphere (elevation 10..80 degrees),
//              drawn at random (area-uniform) from the seed: train = the first 100, test =
//              the last 50 (so test positions differ from train).
//   room360    room [-4,4] x [-4,4] x [0,4] with six textured faces and six objects on
//              the floor near the centre; 150 cameras on an inward orbit (radius 2.8 +-
//              20 %, height 1.0..2.2) looking at the centre region; every 8th a test view.
//   unbalanced room [-5,5] x [-3.5,3.5] x [0,3.2] with five objects, two pillars and a
//              partition wall; 150 cameras along a walk: four dense clusters joined by
//              sparse stretches; every 8th a test view.
//   tworooms   two rooms [-6,0] and [0,6] x [-3,3] x [0,3] joined by a doorway (1.1 m wide,
//              2.1 m high) in the dividing wall at x = 0; three content objects per room
//              (real meshes by default: makeSyntheticScene passes CGAL's animal and figure
//              meshes when none are given); 150 cameras on one walk: a three-quarter arc
//              in the first room, through the door, a three-quarter arc in the second, and
//              looks back towards the first room, most of which the wall hides; every 8th
//              a test view.
//   corridor   three rooms in a row, [-9,9] x [-3,3] x [0,3], divided at x = -3 and x = 3 by
//              walls whose doorways (1.1 m wide) sit on opposite sides; seven content
//              objects; 150 cameras on one walk of uneven density: a slow arc around the
//              first room, through a door, a quick diagonal through the second room, through
//              the other door, a dense cluster of close views of one object in the third
//              and a sparse arc around it; every 8th a test view.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera/camera.h"
#include "geometry/synth/mesh.h"
#include "geometry/synth/texture.h"
#include "geometry/synth/world.h"

namespace saresgs::synth {

// Mesh files and photographs given by the user (already loaded). Meshes are centred,
// scaled to unit radius and rotated so that their up axis is +z.
struct Assets {
  std::vector<TriangleMesh> meshes;
  std::vector<std::string> mesh_paths;
  std::vector<std::shared_ptr<const ImageF>> photos;
  std::vector<std::string> photo_paths;
  Projection projection = Projection::Triplanar;
};

struct LayoutResult {
  std::vector<SceneObject> objects;
  std::vector<Camera> cameras;
  std::vector<int> train, test;
  std::optional<Eigen::AlignedBox3f> room;  // the room's inside, if there is one
};

// The pinhole intrinsics of all layouts: principal point at the image centre, square
// pixels, `fov_deg` across the shorter image side.
Intrinsics layoutIntrinsics(int width, int height, double fov_deg);

// num_views <= 0 selects the layout's default count.
LayoutResult makeObjectLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views);
LayoutResult makeRoom360Layout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views);
LayoutResult makeUnbalancedLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views);
LayoutResult makeTwoRoomsLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views);
LayoutResult makeCorridorLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views);

// The real meshes the tworooms layout uses when no mesh file is given (cgal:NAME specs
// for resolveAsset; their up axis is +y).
const std::vector<std::string>& twoRoomsDefaultMeshes();

}  // namespace saresgs::synth
