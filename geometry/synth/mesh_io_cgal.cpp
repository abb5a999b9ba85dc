// CGAL lives in this file only: CGAL::CGAL adds -frounding-math to every file of the
// target that links it (third_party_notes/cgal.md), so it is kept in a small library of its own.
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <filesystem>

#include "geometry/error.h"
#include "geometry/synth/mesh.h"

namespace saresgs {

TriangleMesh readMeshFile(const std::string& path) {
  using Point = CGAL::Simple_cartesian<double>::Point_3;
  if (!std::filesystem::exists(path)) throw InputError(path, "file", "mesh file does not exist");
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  if (!CGAL::IO::read_polygon_soup(path, points, polygons))
    throw InputError(path, "file", "expected an OFF, PLY or OBJ mesh that CGAL can read");
  TriangleMesh mesh;
  mesh.vertices.reserve(points.size());
  for (const auto& p : points)
    mesh.vertices.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& poly = polygons[f];
    for (std::size_t v : poly)
      if (v >= points.size()) throw InputError(path, "face " + std::to_string(f), "vertex index out of range");
    for (std::size_t k = 1; k + 1 < poly.size(); ++k)
      mesh.faces.emplace_back(static_cast<int>(poly[0]), static_cast<int>(poly[k]), static_cast<int>(poly[k + 1]));
  }
  for (const auto& v : mesh.vertices)
    if (!v.allFinite()) throw InputError(path, "vertices", "expected finite coordinates");
  if (mesh.faces.empty()) throw InputError(path, "faces", "expected at least one triangle");
  return mesh;
}

}  // namespace saresgs
