#include "sim/session_script.h"

#include <filesystem>

#include "core/error.h"
#include "people/random.h"

namespace mmh::sim {
namespace {

// x of the resting proxy in the table frame [m]: left of the play area, clear of the hand.
constexpr double kRestingProxyX = -0.32;

}  // namespace

StoryScript::StoryScript(const people::PeopleConfig& people, const TableSceneOptions& scene)
    : StoryScript(people, scene, people.scenario.story, people.scenario.object, "scenario.object") {}

StoryScript::StoryScript(const people::PeopleConfig& people, const TableSceneOptions& scene,
                         const std::string& story_file, int object, const std::string& object_key)
    : people_(&people),
      story_file_(story_file),
      story_(people::LoadStory(story_file, scene)),
      object_(object) {
  if (object < 0 || object >= static_cast<int>(story_.objects.size())) {
    ThrowBadValue(object_key, std::to_string(object),
                  "an object of " + story_file + " (0.." +
                      std::to_string(story_.objects.size() - 1) + ")");
  }
  const int animator = people.scenario.animator;
  if (animator < 0) ThrowBadValue("scenario.animator", std::to_string(animator), "an index >= 0");
  participant_ = people::DrawParticipant(people.population, animator);
}

std::string StoryScript::ProxyFile() const {
  const std::string& proxy = story_.objects.at(object_).proxy;
  if (proxy.empty()) return "";
  const std::filesystem::path path(proxy);
  if (path.is_absolute()) return proxy;
  return (std::filesystem::path(story_file_).parent_path() / path).lexically_normal().string();
}

people::PerformedTake StoryScript::Perform(int take) const {
  return people::PerformTake(story_, object_, participant_.animator, take, people_->performance,
                     people::ParticipantSeed(people_->population, participant_.index));
}

people::AnnotationSession StoryScript::Annotate(const people::PerformedTake& take) const {
  people::AnnotatorOptions annotator = people_->annotator;
  annotator.frame_rate = people_->performance.frame_rate;
  const std::uint64_t seed = people::ParticipantSeed(people_->population, participant_.index);
  return people::AnnotateTake(take.quality.quality, participant_.annotator, annotator,
                      people::DeriveSeed(seed, {0x616eull, static_cast<std::uint64_t>(take.object),
                                        static_cast<std::uint64_t>(take.take)}));
}

SessionFrames StoryScript::RecordingFrames(const people::PerformedTake& take, int frames) const {
  SessionFrames s;
  s.table_T_proxy.assign(take.table_T_proxy.poses.begin(),
                         take.table_T_proxy.poses.begin() + frames);
  s.slider.assign(frames, people_->annotator.start_value);
  return s;
}

SessionFrames StoryScript::AnnotationFrames(const people::AnnotationSession& annotation,
                                            int frames) const {
  SessionFrames s;
  s.table_T_proxy.assign(frames, RestingTableTProxy());
  s.slider.assign(annotation.slider.begin(), annotation.slider.begin() + frames);
  s.hand = TableTopScene::Hand::kOnSlider;
  return s;
}

Rigid3 RestingTableTProxy() {
  return Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(kRestingProxyX, 0, 0));
}

}  // namespace mmh::sim
