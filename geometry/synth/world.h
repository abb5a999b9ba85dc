#pragma once
// The contents of a built synthetic scene (internal to geometry/synth): objects in world
// coordinates with their textures, the lighting, and the Embree scenes that trace them.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/synth/mesh.h"
#include "geometry/synth/ray_tracer.h"
#include "geometry/synth/texture.h"

namespace saresgs::synth {

struct SceneObject {
  std::string name;         // e.g. "room_floor", "torus"
  std::string mesh_source;  // "procedural:torus" or the mesh file path
  TriangleMesh mesh;        // world coordinates
  // The object's own frame, in which its texture is defined (world = to_world * local).
  Eigen::Affine3f to_world = Eigen::Affine3f::Identity();
  std::shared_ptr<const Texture> texture;
  bool casts_shadow = true;  // the room shell does not (the light comes from outside)
};

// One directional light plus ambient: colour = albedo * (ambient + diffuse * max(0, n.l))
// (+ specular * (n.h)^shininess when asked), with the diffuse and specular terms
// dropped in shadow.
struct Lighting {
  Eigen::Vector3f to_light = Eigen::Vector3f(0.55f, 0.35f, 0.76f).normalized();
  float ambient = 0.4f;
  float diffuse = 0.65f;
  float specular = 0.25f;
  float shininess = 48.0f;
  float shadow_epsilon = 1e-3f;  // shadow rays start this far off the surface
};

}  // namespace saresgs::synth

namespace saresgs {

class SyntheticWorld {
 public:
  SyntheticWorld(std::vector<synth::SceneObject> objects, synth::Lighting lighting);

  const std::vector<synth::SceneObject>& objects() const { return objects_; }
  const synth::Lighting& lighting() const { return lighting_; }
  const synth::RayTracer& tracer() const { return tracer_; }
  const synth::RayTracer& casters() const { return casters_; }
  // Unit area-weighted vertex normals of object k (world frame).
  const std::vector<Eigen::Vector3f>& normals(int k) const { return normals_[k]; }
  // Local frame of object k: inverse transform and the rotation part for normals.
  const Eigen::Affine3f& toLocal(int k) const { return to_local_[k]; }
  const Eigen::Matrix3f& normalToLocal(int k) const { return normal_to_local_[k]; }
  // Cumulative triangle areas over all objects, and (object, face) per entry.
  const std::vector<double>& areaCdf() const { return area_cdf_; }
  const std::vector<std::pair<int, int>>& areaFaces() const { return area_faces_; }

 private:
  static std::vector<const TriangleMesh*> meshPointers(const std::vector<synth::SceneObject>& o, bool casters_only);
  static std::vector<int> objectIds(const std::vector<synth::SceneObject>& o, bool casters_only);

  std::vector<synth::SceneObject> objects_;
  synth::Lighting lighting_;
  std::vector<std::vector<Eigen::Vector3f>> normals_;
  std::vector<Eigen::Affine3f> to_local_;
  std::vector<Eigen::Matrix3f> normal_to_local_;
  std::vector<double> area_cdf_;
  std::vector<std::pair<int, int>> area_faces_;
  synth::RayTracer tracer_;   // everything
  synth::RayTracer casters_;  // objects that cast shadows
};

}  // namespace saresgs
