// montage.glb of one animator's run (`mmh run`): the run's proxy, its montage, and every take
// warped to the reference timeline and as recorded (report/trajectory_glb.h, MontageScene).
#pragma once

#include "pipeline/animator_run.h"
#include "report/gltf_scene.h"

namespace mmh::report {

// The montage of the tracked takes (truth = false: run.montage and the takes' tracked poses) or of
// the ground truth (run.truth_montage and the performed poses), table frame.
GltfScene RunMontageScene(const pipeline::AnimatorRun& run, bool truth, int reference_take);

}  // namespace mmh::report
