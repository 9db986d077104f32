#include "core/camera.h"

#include <cmath>

#include "core/error.h"

namespace mmh {

void PinholeIntrinsics::Validate(const std::string& prefix) const {
  constexpr int kMaxSize = 16384;
  if (width < 1 || width > kMaxSize) {
    ThrowBadValue(prefix + ".width", std::to_string(width), "an image width in [1, 16384] px");
  }
  if (height < 1 || height > kMaxSize) {
    ThrowBadValue(prefix + ".height", std::to_string(height), "an image height in [1, 16384] px");
  }
  if (!std::isfinite(fx) || fx <= 0) {
    ThrowBadValue(prefix + ".fx", FormatNumber(fx), "a finite focal length > 0 px");
  }
  if (!std::isfinite(fy) || fy <= 0) {
    ThrowBadValue(prefix + ".fy", FormatNumber(fy), "a finite focal length > 0 px");
  }
  if (!std::isfinite(cx) || cx < -width || cx > 2.0 * width) {
    ThrowBadValue(
        prefix + ".cx", FormatNumber(cx),
        "a principal point within one image width of the image (" + std::to_string(width) + " px)");
  }
  if (!std::isfinite(cy) || cy < -height || cy > 2.0 * height) {
    ThrowBadValue(prefix + ".cy", FormatNumber(cy),
                  "a principal point within one image height of the image (" +
                      std::to_string(height) + " px)");
  }
}

bool operator==(const PinholeIntrinsics& a, const PinholeIntrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy;
}

}  // namespace mmh
