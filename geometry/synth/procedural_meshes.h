#pragma once
// Procedural triangle meshes and mesh helpers for the synthetic scenes.
// Every closed shape is oriented outward (counter-clockwise seen from outside). Shapes
// with sharp edges (box, cylinder and cone rims) get separate vertices per smooth
// patch, so that area-weighted vertex normals keep the edges sharp.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/synth/mesh.h"

namespace saresgs::synth {

// Sphere of `radius` at the origin; `slices` around z, `stacks` from pole to pole.
TriangleMesh makeSphere(float radius, int slices = 64, int stacks = 32);
// Torus around the z axis: ring radius `major`, tube radius `minor`.
TriangleMesh makeTorus(float major, float minor, int ring_segments = 64, int tube_segments = 32);
// Axis-aligned box with corners `lo` and `hi`; each face is split into n x n quads.
TriangleMesh makeBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, int n = 1);
// Closed cylinder around z from z = 0 to z = height.
TriangleMesh makeCylinder(float radius, float height, int segments = 64);
// Closed cone around z: base disc at z = 0, apex at z = height.
TriangleMesh makeCone(float radius, float height, int segments = 64);
// Superquadric |x/a|^(2/e2) ... with exponents e1 (latitude) and e2 (longitude):
// e = 1 is an ellipsoid, e < 1 boxier, e > 1 pinched.
TriangleMesh makeSuperquadric(const Eigen::Vector3f& radii, float e1, float e2, int slices = 64, int stacks = 32);
// A sphere whose radius is modulated by smooth noise: radius * (1 + amplitude * noise).
TriangleMesh makeBumpyBlob(float radius, float amplitude, float frequency, std::uint64_t seed, int slices = 96,
                           int stacks = 48);

// The inside of an axis-aligned box as six separate quads, oriented inward, each split
// into n x n quads: floor (z = lo), ceiling (z = hi), walls x = lo, x = hi, y = lo, y = hi.
struct RoomFaces {
  TriangleMesh floor, ceiling, wall_xlo, wall_xhi, wall_ylo, wall_yhi;
};
RoomFaces makeRoom(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, int n = 1);

// Helpers.
void appendMesh(TriangleMesh& dst, const TriangleMesh& src);
TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Affine3f& T);
void flipOrientation(TriangleMesh& mesh);
// Per-vertex normals: the area-weighted average of the adjacent faces' normals
// (zero-area faces contribute nothing; isolated vertices get +z).
std::vector<Eigen::Vector3f> vertexNormals(const TriangleMesh& mesh);
Eigen::AlignedBox3f boundingBox(const TriangleMesh& mesh);
double surfaceArea(const TriangleMesh& mesh);
// Moves the bounding-box centre to the origin and scales so that the farthest vertex
// is at distance `radius`. Returns the transform that was applied.
Eigen::Affine3f normaliseMesh(TriangleMesh& mesh, float radius = 1.0f);
// The rotation that takes the given up axis ("x", "y" or "z") to +z (right-handed).
// Throws InputError naming the option for other values.
Eigen::Matrix3f upAxisRotation(const std::string& up_axis);

}  // namespace saresgs::synth
