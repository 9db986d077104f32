// The config section of `mmh track` and `mmh eval` is "track"; before 2026-11 it was "run",
// which is `mmh run`'s section. Header-only: `mmh eval` runs in the light executable, which must
// not link the tracker (docs/architecture.md, "Start-up").
#pragma once

#include "core/config.h"
#include "core/error.h"

namespace mmh::track {

// InputError for a section "run" in an mmh track or mmh eval config, with the hint to rename it.
inline void RefuseRunSection(const Config& config) {
  if (config.root().contains("run")) {
    ThrowBadValue("run", "a section of an mmh track or mmh eval config",
                  "its keys in the section \"track\" (\"run\" is mmh run's section: "
                  "rename it, e.g. --set track.object=1)");
  }
}

}  // namespace mmh::track
