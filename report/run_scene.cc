#include "report/run_scene.h"

#include "report/trajectory_glb.h"

namespace mmh::report {

GltfScene RunMontageScene(const pipeline::AnimatorRun& run, bool truth, int reference_take) {
  const montage::Montage& montage = truth ? run.truth_montage : run.montage;
  MontageObject object;
  object.mesh = run.proxy_model.face_count() > 0 ? run.proxy_model : OrientedStandIn();
  object.montage = montage.trajectory;
  for (const pipeline::TakeRun& take : run.takes) {
    object.takes.push_back(truth ? take.truth : take.tracked);
  }
  object.warps = montage.warps;
  object.reference_take = reference_take;
  return MontageScene({object});
}

}  // namespace mmh::report
