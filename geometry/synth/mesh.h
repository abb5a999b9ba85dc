#pragma once
// Indexed triangle meshes: the data that synthetic scenes are built from.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace saresgs {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> faces;  // counter-clockwise seen from outside
};

// Reads OFF, PLY or OBJ with CGAL's IO (polygons are triangulated as fans). Throws
// InputError naming the file when it is missing, unreadable or has no triangles.
TriangleMesh readMeshFile(const std::string& path);

}  // namespace saresgs
