#pragma once
// Short names for the real assets that Debian packages ship:
//   cgal:NAME      a mesh from libcgal-demo's data.tar.gz (CC0), e.g. cgal:bunny00,
//                  extracted once into the data cache;
//   opencv:FILE    a photograph from opencv-doc's examples, e.g. opencv:baboon.jpg.
// Anything else is returned unchanged (a path).
#include <string>

namespace saresgs {

// The cache folder: $SARESGS_DATA_CACHE, else ./data_cache (git-ignored).
std::string dataCacheDir();
// Resolves a spec to a readable path; throws InputError naming the spec when the
// package or the named asset is missing.
std::string resolveAsset(const std::string& spec);

}  // namespace saresgs
