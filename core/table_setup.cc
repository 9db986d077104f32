#include "core/table_setup.h"

#include "core/error.h"

namespace mmh {

void TableSetup::Validate(const std::string& where) const {
  RequirePositive(play_area_width, where + ".play_area_width", "m");
  RequirePositive(play_area_depth, where + ".play_area_depth", "m");
  RequireFinite(like_box_center_x, where + ".like_box_center_x");
  RequireFinite(like_box_center_y, where + ".like_box_center_y");
  RequireNonNegative(like_box_length, where + ".like_box_length", "m");
  RequirePositive(slider_block_size, where + ".slider_block_size", "m");
  if (has_like_box()) {
    RequirePositive(like_box_width, where + ".like_box_width", "m");
    if (!(like_box_length > slider_block_size)) {
      ThrowBadValue(where + ".like_box_length", FormatNumber(like_box_length),
                    "more than slider_block_size = " + FormatNumber(slider_block_size) + " m");
    }
  }
}

}  // namespace mmh
