#include "geometry/image/contact_sheet.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace saresgs {

Image8 makeContactSheet(const std::vector<ContactSheetItem>& items, int columns, int thumb_width) {
  if (items.empty()) return Image8(thumb_width, thumb_width, 3, 255);
  const Image8& first = *items.front().image;
  const int tw = thumb_width;
  const int th = std::max(1, first.height * tw / std::max(1, first.width));
  const int gap = 4;
  const int cols = std::min<int>(columns, static_cast<int>(items.size()));
  const int rows = (static_cast<int>(items.size()) + cols - 1) / cols;
  cv::Mat sheet(rows * (th + gap) + gap, cols * (tw + gap) + gap, CV_8UC3, cv::Scalar(40, 40, 40));
  for (size_t k = 0; k < items.size(); ++k) {
    const Image8& im = *items[k].image;
    cv::Mat src(im.height, im.width, CV_8UC3, const_cast<std::uint8_t*>(im.data.data()));
    cv::Mat thumb;
    cv::resize(src, thumb, cv::Size(tw, th), 0, 0, cv::INTER_AREA);
    const int x = gap + static_cast<int>(k % cols) * (tw + gap);
    const int y = gap + static_cast<int>(k / cols) * (th + gap);
    thumb.copyTo(sheet(cv::Rect(x, y, tw, th)));
    if (items[k].highlight)  // RGB order: orange frame
      cv::rectangle(sheet, cv::Rect(x, y, tw, th), cv::Scalar(255, 140, 0), 2);
    const cv::Point org(x + 4, y + 14);
    cv::putText(sheet, items[k].label, org, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(sheet, items[k].label, org, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  Image8 out(sheet.cols, sheet.rows, 3);
  for (int r = 0; r < sheet.rows; ++r)
    std::copy(sheet.ptr(r), sheet.ptr(r) + sheet.cols * 3, &out.data[out.index(0, r)]);
  return out;
}

}  // namespace saresgs
