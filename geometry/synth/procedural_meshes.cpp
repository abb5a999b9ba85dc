#include "geometry/synth/procedural_meshes.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include "geometry/error.h"
#include "geometry/synth/noise.h"

namespace saresgs::synth {

namespace {

constexpr float kPiF = std::numbers::pi_v<float>;

// Adds triangle (a, b, c), reversed if needed so that its normal has a positive
// component along `outward`.
void addOriented(TriangleMesh& m, int a, int b, int c, const Eigen::Vector3f& outward) {
  const Eigen::Vector3f n = (m.vertices[b] - m.vertices[a]).cross(m.vertices[c] - m.vertices[a]);
  if (n.dot(outward) < 0) std::swap(b, c);
  m.faces.emplace_back(a, b, c);
}

Eigen::Vector3f centroid(const TriangleMesh& m, int a, int b, int c) {
  return (m.vertices[a] + m.vertices[b] + m.vertices[c]) / 3.0f;
}

// A closed surface over (u, v) in [0,1) x [0,1], periodic in u, with the v = 0 and
// v = 1 rows collapsed to single pole vertices. `outward(p)` orients the faces.
TriangleMesh polarSurface(int slices, int stacks, const std::function<Eigen::Vector3f(float, float)>& f,
                          const std::function<Eigen::Vector3f(const Eigen::Vector3f&)>& outward) {
  slices = std::max(slices, 3);
  stacks = std::max(stacks, 2);
  TriangleMesh m;
  m.vertices.push_back(f(0.0f, 0.0f));  // pole at v = 0
  for (int j = 1; j < stacks; ++j)
    for (int i = 0; i < slices; ++i)
      m.vertices.push_back(f(static_cast<float>(i) / slices, static_cast<float>(j) / stacks));
  m.vertices.push_back(f(0.0f, 1.0f));  // pole at v = 1
  const int south = static_cast<int>(m.vertices.size()) - 1;
  auto idx = [&](int i, int j) { return 1 + (j - 1) * slices + (i % slices); };
  auto add = [&](int a, int b, int c) { addOriented(m, a, b, c, outward(centroid(m, a, b, c))); };
  for (int i = 0; i < slices; ++i) {
    add(0, idx(i, 1), idx(i + 1, 1));
    add(south, idx(i, stacks - 1), idx(i + 1, stacks - 1));
    for (int j = 1; j + 1 < stacks; ++j) {
      add(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1));
      add(idx(i, j), idx(i + 1, j + 1), idx(i, j + 1));
    }
  }
  return m;
}

Eigen::Vector3f fromOrigin(const Eigen::Vector3f& p) { return p; }

float signedPow(float x, float e) { return std::copysign(std::pow(std::abs(x), e), x); }

}  // namespace

TriangleMesh makeSphere(float radius, int slices, int stacks) {
  return polarSurface(
      slices, stacks,
      [&](float u, float v) {
        const float th = kPiF * v, ph = 2 * kPiF * u;
        return Eigen::Vector3f(radius * std::sin(th) * std::cos(ph), radius * std::sin(th) * std::sin(ph),
                               radius * std::cos(th));
      },
      fromOrigin);
}

TriangleMesh makeSuperquadric(const Eigen::Vector3f& radii, float e1, float e2, int slices, int stacks) {
  return polarSurface(
      slices, stacks,
      [&](float u, float v) {
        const float eta = kPiF * (0.5f - v), om = 2 * kPiF * u - kPiF;
        const float ce = signedPow(std::cos(eta), e1), se = signedPow(std::sin(eta), e1);
        return Eigen::Vector3f(radii.x() * ce * signedPow(std::cos(om), e2),
                               radii.y() * ce * signedPow(std::sin(om), e2), radii.z() * se);
      },
      fromOrigin);
}

TriangleMesh makeBumpyBlob(float radius, float amplitude, float frequency, std::uint64_t seed, int slices, int stacks) {
  return polarSurface(
      slices, stacks,
      [&](float u, float v) {
        const float th = kPiF * v, ph = 2 * kPiF * u;
        const Eigen::Vector3f d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
        // Noise sampled on the unit sphere, so the seam and the poles match up.
        const float n = fbm(d * frequency, 3, seed);
        return Eigen::Vector3f(d * radius * (1.0f + amplitude * n));
      },
      fromOrigin);
}

TriangleMesh makeTorus(float major, float minor, int ring_segments, int tube_segments) {
  const int nu = std::max(ring_segments, 3), nv = std::max(tube_segments, 3);
  TriangleMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const float ph = 2 * kPiF * i / nu, th = 2 * kPiF * j / nv;
      const float r = major + minor * std::cos(th);
      m.vertices.emplace_back(r * std::cos(ph), r * std::sin(ph), minor * std::sin(th));
    }
  auto idx = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  auto outward = [&](const Eigen::Vector3f& p) {
    Eigen::Vector3f ring(p.x(), p.y(), 0);
    ring = ring.norm() > 0 ? Eigen::Vector3f(ring.normalized() * major) : ring;
    return Eigen::Vector3f(p - ring);
  };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const int a = idx(i, j), b = idx(i + 1, j), c = idx(i + 1, j + 1), d = idx(i, j + 1);
      addOriented(m, a, b, c, outward(centroid(m, a, b, c)));
      addOriented(m, a, c, d, outward(centroid(m, a, c, d)));
    }
  return m;
}

namespace {

// A planar grid patch: origin + s * du + t * dv for s, t in [0,1], n x n quads, with
// its own vertices, oriented along `normal`.
void addPatch(TriangleMesh& m, const Eigen::Vector3f& origin, const Eigen::Vector3f& du, const Eigen::Vector3f& dv,
              int n, const Eigen::Vector3f& normal) {
  n = std::max(n, 1);
  const int base = static_cast<int>(m.vertices.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.vertices.push_back(origin + du * (static_cast<float>(i) / n) + dv * (static_cast<float>(j) / n));
  auto idx = [&](int i, int j) { return base + j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      addOriented(m, idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), normal);
      addOriented(m, idx(i, j), idx(i + 1, j + 1), idx(i, j + 1), normal);
    }
}

void addBoxFaces(TriangleMesh& m, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, int n, float sign) {
  const Eigen::Vector3f e = hi - lo;
  const Eigen::Vector3f X(e.x(), 0, 0), Y(0, e.y(), 0), Z(0, 0, e.z());
  addPatch(m, lo, X, Y, n, sign * -Eigen::Vector3f::UnitZ());
  addPatch(m, lo + Z, X, Y, n, sign * Eigen::Vector3f::UnitZ());
  addPatch(m, lo, Y, Z, n, sign * -Eigen::Vector3f::UnitX());
  addPatch(m, lo + X, Y, Z, n, sign * Eigen::Vector3f::UnitX());
  addPatch(m, lo, X, Z, n, sign * -Eigen::Vector3f::UnitY());
  addPatch(m, lo + Y, X, Z, n, sign * Eigen::Vector3f::UnitY());
}

// A disc at height z facing `up` (+1) or down (-1), with its own vertices.
void addDisc(TriangleMesh& m, float radius, float z, int segments, float up) {
  const int centre = static_cast<int>(m.vertices.size());
  m.vertices.emplace_back(0, 0, z);
  for (int i = 0; i < segments; ++i) {
    const float ph = 2 * kPiF * i / segments;
    m.vertices.emplace_back(radius * std::cos(ph), radius * std::sin(ph), z);
  }
  for (int i = 0; i < segments; ++i)
    addOriented(m, centre, centre + 1 + i, centre + 1 + (i + 1) % segments, Eigen::Vector3f(0, 0, up));
}

}  // namespace

TriangleMesh makeBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, int n) {
  TriangleMesh m;
  addBoxFaces(m, lo, hi, n, 1.0f);
  return m;
}

RoomFaces makeRoom(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, int n) {
  const Eigen::Vector3f e = hi - lo;
  const Eigen::Vector3f X(e.x(), 0, 0), Y(0, e.y(), 0), Z(0, 0, e.z());
  RoomFaces r;
  addPatch(r.floor, lo, X, Y, n, Eigen::Vector3f::UnitZ());
  addPatch(r.ceiling, lo + Z, X, Y, n, -Eigen::Vector3f::UnitZ());
  addPatch(r.wall_xlo, lo, Y, Z, n, Eigen::Vector3f::UnitX());
  addPatch(r.wall_xhi, lo + X, Y, Z, n, -Eigen::Vector3f::UnitX());
  addPatch(r.wall_ylo, lo, X, Z, n, Eigen::Vector3f::UnitY());
  addPatch(r.wall_yhi, lo + Y, X, Z, n, -Eigen::Vector3f::UnitY());
  return r;
}

TriangleMesh makeCylinder(float radius, float height, int segments) {
  segments = std::max(segments, 3);
  TriangleMesh m;
  // Side: a ring at the bottom and one at the top, shared only within the side.
  const int base = 0;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < segments; ++i) {
      const float ph = 2 * kPiF * i / segments;
      m.vertices.emplace_back(radius * std::cos(ph), radius * std::sin(ph), k * height);
    }
  for (int i = 0; i < segments; ++i) {
    const int a = base + i, b = base + (i + 1) % segments;
    const int c = b + segments, d = a + segments;
    const Eigen::Vector3f mid = (m.vertices[a] + m.vertices[b]) * 0.5f;
    const Eigen::Vector3f out(mid.x(), mid.y(), 0);
    addOriented(m, a, b, c, out);
    addOriented(m, a, c, d, out);
  }
  addDisc(m, radius, 0, segments, -1);
  addDisc(m, radius, height, segments, 1);
  return m;
}

TriangleMesh makeCone(float radius, float height, int segments) {
  segments = std::max(segments, 3);
  TriangleMesh m;
  // The side is a band of rings up to a small top ring and an apex point, so that the
  // smooth normals near the apex are not averaged over one huge fan.
  const int rings = 8;
  for (int k = 0; k < rings; ++k) {
    const float s = static_cast<float>(k) / rings;
    for (int i = 0; i < segments; ++i) {
      const float ph = 2 * kPiF * i / segments;
      m.vertices.emplace_back((1 - s) * radius * std::cos(ph), (1 - s) * radius * std::sin(ph), s * height);
    }
  }
  const int apex = static_cast<int>(m.vertices.size());
  m.vertices.emplace_back(0, 0, height);
  auto idx = [&](int i, int k) { return k * segments + (i % segments); };
  auto outward = [&](const Eigen::Vector3f& p) {
    return Eigen::Vector3f(p.x() * height, p.y() * height, radius * std::hypot(p.x(), p.y()));
  };
  for (int i = 0; i < segments; ++i) {
    for (int k = 0; k + 1 < rings; ++k) {
      const int a = idx(i, k), b = idx(i + 1, k), c = idx(i + 1, k + 1), d = idx(i, k + 1);
      addOriented(m, a, b, c, outward(centroid(m, a, b, c)));
      addOriented(m, a, c, d, outward(centroid(m, a, c, d)));
    }
    const int a = idx(i, rings - 1), b = idx(i + 1, rings - 1);
    addOriented(m, a, b, apex, outward(centroid(m, a, b, apex)));
  }
  addDisc(m, radius, 0, segments, -1);
  return m;
}

void appendMesh(TriangleMesh& dst, const TriangleMesh& src) {
  const int base = static_cast<int>(dst.vertices.size());
  dst.vertices.insert(dst.vertices.end(), src.vertices.begin(), src.vertices.end());
  for (const auto& f : src.faces) dst.faces.push_back(f + Eigen::Vector3i::Constant(base));
}

TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Affine3f& T) {
  TriangleMesh out = mesh;
  for (auto& v : out.vertices) v = T * v;
  if (T.linear().determinant() < 0) flipOrientation(out);
  return out;
}

void flipOrientation(TriangleMesh& mesh) {
  for (auto& f : mesh.faces) std::swap(f[1], f[2]);
}

std::vector<Eigen::Vector3f> vertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> n(mesh.vertices.size(), Eigen::Vector3f::Zero());
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3f& a = mesh.vertices[f[0]];
    // The unnormalised cross product is twice the area times the unit normal.
    const Eigen::Vector3f c = (mesh.vertices[f[1]] - a).cross(mesh.vertices[f[2]] - a);
    for (int k = 0; k < 3; ++k) n[f[k]] += c;
  }
  for (auto& v : n) {
    const float len = v.norm();
    v = len > 0 ? Eigen::Vector3f(v / len) : Eigen::Vector3f::UnitZ();
  }
  return n;
}

Eigen::AlignedBox3f boundingBox(const TriangleMesh& mesh) {
  Eigen::AlignedBox3f box;
  for (const auto& v : mesh.vertices) box.extend(v);
  return box;
}

double surfaceArea(const TriangleMesh& mesh) {
  double area = 0;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
    area += 0.5 * (mesh.vertices[f[1]].cast<double>() - a).cross(mesh.vertices[f[2]].cast<double>() - a).norm();
  }
  return area;
}

Eigen::Affine3f normaliseMesh(TriangleMesh& mesh, float radius) {
  const Eigen::Vector3f c = boundingBox(mesh).center();
  float r = 0;
  for (const auto& v : mesh.vertices) r = std::max(r, (v - c).norm());
  const float s = r > 0 ? radius / r : 1.0f;
  Eigen::Affine3f T = Eigen::Affine3f::Identity();
  T.scale(s);
  T.translate(-c);
  for (auto& v : mesh.vertices) v = T * v;
  return T;
}

Eigen::Matrix3f upAxisRotation(const std::string& up_axis) {
  Eigen::Matrix3f R;
  if (up_axis == "z") {
    R.setIdentity();
  } else if (up_axis == "y") {
    // (x, y, z) -> (x, -z, y): +y becomes +z.
    R << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  } else if (up_axis == "x") {
    // (x, y, z) -> (-z, y, x): +x becomes +z.
    R << 0, 0, -1, 0, 1, 0, 1, 0, 0;
  } else {
    throw InputError("options", "up_axis", "expected x, y or z, got '" + up_axis + "'");
  }
  return R;
}

}  // namespace saresgs::synth
