#pragma once
// The kernel of the observed voxels' dilation (OccupancyGrids, VdbMask, the OpenVDB module).

namespace saresgs {

// Neighbourhood of one dilation step; r steps give:
//   Cube        26-neighbourhood (OpenVDB NN_FACE_EDGE_VERTEX): max_a |d_a| <= r, the
//               (2r+1)^3 cube. The default: the paper's "3D kernel of radius r" with no
//               further shape given; the cube is the kernel of a plain 3D max filter.
//   FaceEdge    18-neighbourhood (NN_FACE_EDGE): max |d_a| <= r and |d|_1 <= 2r.
//   Octahedron  6-neighbourhood (NN_FACE): |d|_1 <= r.
enum class DilationShape { Cube, FaceEdge, Octahedron };

}  // namespace saresgs
