// Full fidelity's sessions (`run.fidelity = "full"`): every recording and annotation session of a
// run rendered by the Kinect model (sim/) and tracked by the real tracker and slider reader
// (track/). RunAnimator (pipeline/animator_run.h) calls them through a registration, not by name,
// so that a program that runs fast fidelity only links neither the renderer (Embree) nor the
// tracker (PCL, OpenCV): the light `mmh` runs `run` and `study` in fast fidelity and hands full
// fidelity to `mmh-full` (docs/architecture.md, "Start-up"). pipeline/recorded_sessions.cc is the
// object library mmh::pipeline_sessions; linking it registers RecordSessions at start-up
// (mmh-full, the tests, the benchmarks).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/triangle_mesh.h"
#include "pipeline/animator_run.h"
#include "sim/session_script.h"

namespace mmh::pipeline {

// The stories' scripts of a run: the scenario's, and the practice story's (run.practice).
struct RunScripts {
  explicit RunScripts(const RunConfig& config);
  sim::StoryScript main;
  std::optional<sim::StoryScript> practice;
};

// The proxies' models: rendered by the sensor, given to the tracker, and the metrics' points.
// meshes[0] is the takes' (render.proxy, or the story object's), meshes[1] the practice take's.
struct ProxyModels {
  std::vector<TriangleMesh> meshes;
  std::vector<std::string> names;  // for messages: the file, or "the Soldier"
  // The scene's own static objects (sim::LoadSceneObjects of the render config's scene), loaded
  // once for every session.
  std::vector<TriangleMesh> scene_objects;
};

// Renders and tracks every session of the takes not `loaded` (the recording of each, and the
// annotation of each but the practice take; takes[0] is the practice take when the scripts have
// one) and fills in their results. Returns the frames rendered; sets seconds.record and
// seconds.annotate. Results do not depend on the thread count.
using SessionRecorder = int (*)(const RunConfig& config, const RunScripts& scripts,
                                const ProxyModels& models, const std::vector<bool>& loaded,
                                const Progress& progress, std::vector<TakeRun>& takes,
                                StageSeconds& seconds);

// Called once, at start-up, by pipeline/recorded_sessions.cc. Returns true.
bool RegisterSessionRecorder(SessionRecorder recorder);

// The registered recorder, or nullptr in a program that does not link mmh::pipeline_sessions.
SessionRecorder RegisteredSessionRecorder();

// The take as the system has it: `poses` (table_T_proxy; those of lost frames are ignored) with
// the lost frames filled for the compositor (FillGaps), on the ground truth's timestamps.
void SetTracked(std::vector<Rigid3> poses, std::vector<track::TrackStatus> status, TakeRun& take);

}  // namespace mmh::pipeline
