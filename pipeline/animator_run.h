// One animator end to end (`mmh run`): each take of a story performed by a simulated participant,
// recorded through the Kinect model and tracked by the real tracker, annotated with the slider
// block and read by the real slider reader; then the montage from the tracked takes and read
// annotations (as the real system has them) and, for comparison, from the ground truth.
//
// Fidelity: kFull renders every recording and annotation session and runs the tracker and slider
// reader on the frames; kFast skips the frames and applies the measured tracker and slider-reader
// error model (pipeline/error_model.h) to the ground truth, for large sweeps.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/annotation.h"
#include "core/config.h"
#include "core/rigid3.h"
#include "core/trajectory.h"
#include "metrics/tracking_metrics.h"
#include "montage/compose.h"
#include "pipeline/error_model.h"
#include "pipeline/run_metrics.h"
#include "people/annotator.h"
#include "people/performance.h"
#include "people/population.h"
#include "people/scenario.h"
#include "people/story.h"
#include "sim/render_session.h"
#include "track/proxy_tracker.h"
#include "track/slider_reader.h"

namespace mmh::pipeline {

enum class Fidelity {
  kFull,  // render every frame, run the tracker and the slider reader on it
  kFast,  // the measured error model applied to the ground truth (no frames)
};
std::span<const std::pair<Fidelity, const char*>> EnumNames(Fidelity);

// Section "run".
struct RunOptions {
  // Takes of the story's object (scenario.object) recorded, annotated and composited (paper: 3).
  int takes = 3;
  // A practice story (e.g. configs/stories/mario.json) performed once before the takes (paper:
  // "the participants first practised with Mario"): recorded and tracked like a take, not
  // composited; the takes' skill index starts after it. Empty: no practice.
  std::string practice;
  Fidelity fidelity = Fidelity::kFull;
  // Lost frames get a pose for the compositor by interpolating the neighbouring estimates
  // (slerp and lerp; the first or last estimate held at the ends). A take with fewer than
  // min_tracked_share of its frames estimated is a failed take (InputError-like RunError).
  double min_tracked_share = 0.5;
  // Compute metrics.json (per-frame pose errors with ADD/ADD-S, annotation errors, the montage
  // against the ground truth's montage, which is composed only for it). The study's statistics
  // never read them: `mmh study` computes them for replicate 0 only, `mmh calibrate` never.
  bool metrics = true;

  template <class V>
  void VisitFields(V& v) {
    v("takes", takes);
    v("practice", practice);
    v("fidelity", fidelity);
    v("min_tracked_share", min_tracked_share);
    v("metrics", metrics);
  }
  void Validate(const std::string& prefix) const;
};

// Every section of a run config: the render sections (sim/render_session.h), the scenario and the
// people's sections (people/scenario.h: what is performed and by whom), "tracker" and "slider" (track/),
// "montage" (montage::ComposeOptions), "metrics" (metrics::PoseErrorOptions), "error_model"
// (pipeline/error_model.h) and "run". Unknown sections and keys are errors.
struct RunConfig {
  sim::RenderConfig render;
  people::PeopleConfig people;
  track::ProxyTrackerOptions tracker;
  track::SliderReaderOptions slider;
  montage::ComposeOptions montage;
  metrics::PoseErrorOptions metrics;
  ErrorModelOptions error_model;
  RunOptions run;

  // `extra_sections` are accepted and left alone (a study config's "study", "scorers", "viewer").
  static RunConfig FromConfig(const Config& config,
                              const std::vector<std::string>& extra_sections = {});
  nlohmann::json ToJson() const;
  // This config with participant `animator` of the population in the scenario (mmh study runs
  // each of its animators so).
  RunConfig ForAnimator(int animator) const;
};

// One take through the pipeline. Trajectories are table_T_proxy with timestamps i / frame_rate.
struct TakeRun {
  int take = 0;                       // index within the story's object (0-based)
  people::PerformedTake performed;       // ground truth: motion, latent quality, flaws
  people::AnnotationSession annotation;  // ground truth: judgement, delay, slider block (not for the
                                      // practice take, which is not annotated)
  Trajectory truth;    // #frames: the performed motion (render.frames may shorten the take)
  Trajectory tracked;  // #frames, lost frames filled (see RunOptions)
  std::vector<track::TrackStatus> status;  // #frames
  // The depth camera's pose over the table: true, and as the tracker estimated it (the plane it
  // found and the setup's tape marks). Identity for both in fast fidelity.
  Rigid3 camera_T_table;
  Rigid3 estimated_camera_T_table;
  Annotation truth_annotation;     // the slider block's true values
  Annotation read_annotation;      // the slider reader's values (held where not found)
  std::vector<bool> slider_found;  // #frames

  // Share of frames not lost.
  double EstimatedShare() const;
};

struct StageSeconds {
  double perform = 0.0;   // performances and annotator simulations
  double record = 0.0;    // recording sessions: render + track (wall clock, sessions in parallel)
  double annotate = 0.0;  // annotation sessions: render + slider reading
  double compose = 0.0;   // both montages
  double metrics = 0.0;
  double total = 0.0;
};

struct AnimatorRun {
  people::Participant participant;
  std::optional<TakeRun> practice;
  std::vector<TakeRun> takes;
  montage::Montage montage;        // from the tracked takes and read annotations
  montage::Montage truth_montage;  // from the ground truth (empty unless run.metrics)
  TriangleMesh proxy_model;        // the takes' proxy (montage.glb shows it)
  // Latent quality of each montage frame, carried from the takes' frames it shows
  // (people::CompositeQuality).
  std::vector<double> montage_quality;
  std::vector<double> truth_montage_quality;
  std::optional<RunMetrics> metrics;  // metrics.json; only with run.metrics
  StageSeconds seconds;
  int rendered_frames = 0;  // frames rendered and tracked or read (0 in fast fidelity)
};

// progress(done, total) in frames (or in takes in fast fidelity); may be called from any thread,
// never concurrently.
using Progress = std::function<void(std::int64_t done, std::int64_t total)>;

// Called once per take (and for the practice take, with practice = true) as soon as its sessions
// are tracked and read, before anything that may fail later, so that a caller can keep the
// results of the stages that finished.
using TakeDone = std::function<void(const TakeRun& take, bool practice)>;

// Called once per take after it is performed (take.performed, truth and truth_annotation set):
// returns true when it has filled in the take's session results (tracked, status, read
// annotation, slider_found, camera poses) from an earlier run, so that its sessions are not run
// again (`mmh run --resume`).
using TakeLoader = std::function<bool(TakeRun& take, bool practice)>;

// Runs participant config.people.scenario.animator of config.people.population through
// config.run.takes takes of the scenario's story and object. Deterministic in the config,
// independent of the thread count. Throws InputError for bad input (a missing story, takes too short for the
// montage), and a RunError when a take's tracking failed (fewer than run.min_tracked_share of its
// frames estimated), naming the take.
AnimatorRun RunAnimator(const RunConfig& config, const Progress& progress = {},
                        const TakeDone& take_done = {}, const TakeLoader& load = {});

// Whether this program can run full fidelity: it links the recorded sessions
// (pipeline/recorded_sessions.h; the light `mmh` does not, and hands such runs to `mmh-full`).
// RunAnimator throws a std::logic_error for run.fidelity = "full" where this is false.
bool FullFidelityLinked();

// A failure of the work (exit code 1), as opposed to bad input.
class RunError : public std::runtime_error {
 public:
  explicit RunError(const std::string& message) : std::runtime_error(message) {}
};

// Fills the poses of frames without an estimate (`estimated[i]` false) by interpolating between
// the nearest estimated frames (the first or last estimate held at the ends). `poses` has
// estimated.size() entries; at least one must be estimated.
void FillGaps(std::vector<Rigid3>& poses, const std::vector<bool>& estimated);

}  // namespace mmh::pipeline
