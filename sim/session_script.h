// The script of a participant's sessions with a story (paper, "Recording a Take" and "Annotating
// the Takes"): the participant drawn from the population performs take after take of a story's
// object; in a recording session the hand moves the proxy through the take while the slider
// block rests, and in an annotation session the take plays on screen, the proxy rests beside the
// play area and the hand moves the slider block. `mmh render` renders one session, `mmh run` every
// session of every take, and the tracker's tests script theirs here too, so that a take rendered
// by any of them is the same frames.
#pragma once

#include <string>
#include <vector>

#include "core/rigid3.h"
#include "people/scenario.h"
#include "people/story.h"
#include "sim/render_session.h"

namespace mmh::sim {

// What a session shows the sensor, frame by frame.
struct SessionFrames {
  std::vector<Rigid3> table_T_proxy;  // #frames
  std::vector<double> slider;         // #frames [slider units]
  TableTopScene::Hand hand = TableTopScene::Hand::kOnProxy;
};

class StoryScript {
 public:
  // The scenario's story and object (people.scenario), performed by its participant.
  StoryScript(const people::PeopleConfig& people, const TableSceneOptions& scene);
  // Loads and checks `story_file` (InputError naming the file) and the object (InputError naming
  // `object_key` and the story's objects), performed by the scenario's participant
  // (people.scenario.animator of people.population). `people` must outlive the script.
  StoryScript(const people::PeopleConfig& people, const TableSceneOptions& scene,
              const std::string& story_file, int object, const std::string& object_key);

  const people::Story& story() const { return story_; }
  int object() const { return object_; }
  const people::Participant& participant() const { return participant_; }
  // The proxy model file of the story's object ("" for the Soldier; relative paths are relative
  // to the story file).
  std::string ProxyFile() const;

  // Take `take` (0-based; the skill index: a practice take counts) as the participant performs it.
  people::PerformedTake Perform(int take) const;
  // The participant's annotation of a performed take: their slider while it plays.
  people::AnnotationSession Annotate(const people::PerformedTake& take) const;

  // The first `frames` frames of the take's recording session (the block rests at the
  // annotator's start value) and of its annotation session.
  SessionFrames RecordingFrames(const people::PerformedTake& take, int frames) const;
  SessionFrames AnnotationFrames(const people::AnnotationSession& annotation, int frames) const;

 private:
  const people::PeopleConfig* people_;
  std::string story_file_;
  people::Story story_;
  int object_;
  people::Participant participant_;
};

// Where the proxy rests during an annotation session: on the table left of the play area.
Rigid3 RestingTableTProxy();

}  // namespace mmh::sim
