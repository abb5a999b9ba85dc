#pragma once
// Two-view correspondences and the file format through which matchers run elsewhere
// (MASt3R or any other) hand theirs to saresgs.
//
// Pixel coordinates follow the camera convention (geometry/camera/camera.h): pixel (i, j)
// covers [i, i+1) x [j, j+1), its centre is (i + 0.5, j + 0.5).
//
// Matches file (text, UTF-8/ASCII):
//   # comment lines start with '#'; blank lines are ignored anywhere
//   x0,y0,x1,y1                 <- header, required, the first line that is not a comment
//   120.5,64.5,118.25,70.75     <- one correspondence per line: view 0 (x0, y0), view 1 (x1, y1)
// Fields are separated by commas and/or spaces or tabs (so "x0 y0 x1 y1" works too), numbers
// are decimal (C locale, exponents allowed) and must be finite. View 0 is the real
// (training) view, view 1 the extrapolated render. Tools whose pixel centres sit on integer
// coordinates (OpenCV, numpy, MASt3R) are read with MatchesFileOptions::pixel_center = 0.
// Any other line raises InputError(file, "line N", what was expected).
#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

namespace saresgs {

struct Correspondence {
  Eigen::Vector2d x0 = Eigen::Vector2d::Zero();  // in view 0 (the real view)
  Eigen::Vector2d x1 = Eigen::Vector2d::Zero();  // in view 1 (the extrapolated view)
  bool operator==(const Correspondence&) const = default;
};

struct MatchesFileOptions {
  // Where the file puts the centre of the first pixel: 0.5 (saresgs, COLMAP) or 0
  // (OpenCV, numpy, MASt3R). Coordinates are shifted by 0.5 - pixel_center on reading.
  double pixel_center = 0.5;
};

std::vector<Correspondence> readMatches(const std::string& path, const MatchesFileOptions& opts = {});
// Writes the format above (pixel_center 0.5) with 17 significant digits, so that reading
// the file back gives the same doubles; written to a temporary name, then renamed.
void writeMatches(const std::string& path, std::span<const Correspondence> matches);

// Keeps at most one correspondence per stride x stride cell of view 0 (cells start at
// pixel 0): the one whose x0 is nearest the centre of the cell's first pixel, ties to the
// earlier one. For dense per-pixel input this is exactly the pixels (stride*i, stride*j),
// as in the paper (5 px in x and y); for sparse input it thins without moving points.
// Correspondences whose x0 is not finite or lies outside [0, width) x [0, height) are
// dropped. The output is in the order of the cells (row-major), so it is deterministic.
std::vector<Correspondence> subsampleByStride(std::span<const Correspondence> matches, int stride, int width,
                                              int height);

}  // namespace saresgs
