#pragma once
// A contact sheet: thumbnails of many views on one page, labelled, so that a person
// can see at a glance what a dataset holds.
#include <string>
#include <vector>

#include "geometry/image/image.h"

namespace saresgs {

struct ContactSheetItem {
  const Image8* image;  // RGB
  std::string label;    // drawn in the thumbnail's corner
  bool highlight;       // drawn with a coloured frame (e.g. test views)
};

// Lays the items out in rows of `columns`, each scaled to `thumb_width` wide.
Image8 makeContactSheet(const std::vector<ContactSheetItem>& items, int columns = 8, int thumb_width = 160);

}  // namespace saresgs
