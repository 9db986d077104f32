// The report's clocks: at every montage frame, the reference frame it was played from and the
// frame each take shows then, so that the 3D view plays the takes and the montage in sync (issue
// 22). A montage frame f in segment s plays source frame j = source_first + (f - montage_first)
// of take s.take (paper, "Unwarping the Montage"); the reference frame is the first t of the
// segment's reference frames with w_l(t) >= j (the warp is monotone: the reference frame whose
// run of source frames contains j); at t, take K shows its own frame w_K(t) (eq. 1-3), and the
// chosen take shows j itself.
#pragma once

#include <vector>

#include "montage/blend.h"

namespace mmh::report {

struct MontageClock {
  std::vector<int> reference;             // per montage frame: the reference frame t
  std::vector<std::vector<int>> takes;    // [take][montage frame]: the take's own frame
};

// `segments` must tile the montage's frames from 0 and the reference timeline (as
// montage::Unwarp returns them; InputError otherwise), `warps[K]` has one entry per reference
// frame.
MontageClock ComputeMontageClock(const std::vector<montage::MontageSegment>& segments,
                                 const std::vector<std::vector<int>>& warps);

}  // namespace mmh::report
