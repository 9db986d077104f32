#include "pipeline/animator_run.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>

#include "core/error.h"
#include "core/options.h"
#include "pipeline/recorded_sessions.h"
#include "pipeline/run_metrics.h"
#include "people/random.h"
#include "people/viewer.h"

namespace mmh::pipeline {

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr std::pair<Fidelity, const char*> kFidelityNames[] = {{Fidelity::kFull, "full"},
                                                               {Fidelity::kFast, "fast"}};

// Stand-ins for the sessions in fast fidelity: the error model applied to the ground truth.
void SimulateSessions(const RunConfig& config, std::uint64_t seed, TakeRun& take) {
  // The tracker's failures depend on how the camera (placed by the config) sees the pose.
  const sim::CameraPlacement& camera = config.render.camera;
  SimulatedTracking tracking = SimulateTracking(
      take.truth, config.error_model,
      people::DeriveSeed(seed, {0x7472ull, static_cast<std::uint64_t>(take.performed.object),
                             static_cast<std::uint64_t>(take.take)}),
      Eigen::Vector3d(camera.x, camera.y, camera.z));
  SetTracked(std::move(tracking.tracked.poses), std::move(tracking.status), take);
  if (!take.truth_annotation.values.empty()) {
    const SimulatedReading reading = SimulateSliderReading(
        take.truth_annotation, config.error_model,
        people::DeriveSeed(seed, {0x736cull, static_cast<std::uint64_t>(take.performed.object),
                               static_cast<std::uint64_t>(take.take)}));
    take.read_annotation = reading.read;
    take.slider_found = reading.found;
  }
}

// Per montage frame: the take it shows and that take's frame (for carrying latent quality).
std::vector<double> MontageQuality(const montage::Montage& m, const std::vector<TakeRun>& takes) {
  std::vector<std::vector<double>> quality;
  for (const TakeRun& t : takes) quality.push_back(t.performed.quality.quality);
  std::vector<int> take_of_frame, source_frame;
  for (const montage::MontageSegment& s : m.segments) {
    for (int f = s.source_first; f <= s.source_last; ++f) {
      take_of_frame.push_back(s.take);
      source_frame.push_back(f);
    }
  }
  return people::CompositeQuality(quality, take_of_frame, source_frame);
}

// Every take the participant performs, the practice take first, with its ground truth cut to
// render.frames (when set: a quick look, or a short regression test). A performed take that is
// then no longer than the montage's shortest segment is refused now (the montage would refuse it,
// after all the rendering and tracking).
std::vector<TakeRun> PerformTakes(const RunConfig& config, const RunScripts& scripts) {
  std::vector<TakeRun> takes;
  const int practice_takes = scripts.practice ? 1 : 0;
  if (scripts.practice) {
    TakeRun t;
    t.take = 0;
    t.performed = scripts.practice->Perform(0);
    takes.push_back(std::move(t));
  }
  for (int k = 0; k < config.run.takes; ++k) {
    TakeRun t;
    t.take = practice_takes + k;
    t.performed = scripts.main.Perform(t.take);
    t.annotation = scripts.main.Annotate(t.performed);
    takes.push_back(std::move(t));
  }
  const int render_frames = config.render.render.frames;
  for (TakeRun& t : takes) {
    const int frames = render_frames == 0 ? t.performed.frames()
                                          : std::min(render_frames, t.performed.frames());
    t.truth = t.performed.table_T_proxy;
    t.truth.timestamps.resize(frames);
    t.truth.poses.resize(frames);
    if (!t.annotation.slider.empty()) {
      t.truth_annotation = t.annotation.SliderAnnotation(config.people.performance.frame_rate);
      t.truth_annotation.timestamps.resize(frames);
      t.truth_annotation.values.resize(frames);
    }
  }
  const int d = config.montage.labelling.min_segment_length;
  for (std::size_t slot = practice_takes; slot < takes.size(); ++slot) {
    const int frames = static_cast<int>(takes[slot].truth.size());
    if (d > 0 && frames <= d) {
      ThrowBadValue("take " + std::to_string(takes[slot].take) + " of animator " +
                        std::to_string(config.people.scenario.animator) + " (" +
                        config.people.scenario.story + ")",
                    std::to_string(frames) + " frames",
                    "more than montage.labelling.min_segment_length = " + std::to_string(d) +
                        " frames (the shortest segment a montage may take)");
    }
  }
  return takes;
}

// The proxies' models (pipeline/recorded_sessions.h).
ProxyModels LoadProxyModels(const RunConfig& config, const RunScripts& scripts) {
  ProxyModels models;
  const sim::RenderOptions& render = config.render.render;
  const std::string main_proxy = render.proxy.empty() ? scripts.main.ProxyFile() : render.proxy;
  models.meshes.push_back(sim::LoadProxyModel(main_proxy, render.proxy_scale));
  models.names.push_back(main_proxy.empty() ? "the Soldier" : main_proxy);
  if (scripts.practice) {
    const std::string practice_proxy = scripts.practice->ProxyFile();
    models.meshes.push_back(sim::LoadProxyModel(practice_proxy, 1.0));
    models.names.push_back(practice_proxy.empty() ? "the Soldier" : practice_proxy);
  }
  models.scene_objects = sim::LoadSceneObjects(config.render.scene);
  return models;
}

// A take with too few tracked frames fails the run (RunError).
void CheckTracked(const TakeRun& t, const std::string& what, const RunOptions& options) {
  if (t.EstimatedShare() < options.min_tracked_share) {
    throw RunError(what + ": tracking failed: " + FormatNumber(100.0 * t.EstimatedShare()) +
                   " % of its " + std::to_string(t.status.size()) +
                   " frames have a pose, run.min_tracked_share asks for at least " +
                   FormatNumber(100.0 * options.min_tracked_share) +
                   " %; see its status.csv for the reasons");
  }
}

// The system's montage (tracked takes, read annotations) and, with run.metrics, the ground
// truth's, each with the latent quality of its frames.
void ComposeMontages(const RunConfig& config, AnimatorRun& result) {
  std::vector<Trajectory> tracked, truth;
  std::vector<Annotation> read, truth_annotations;
  std::vector<std::string> names;
  for (const TakeRun& t : result.takes) {
    tracked.push_back(t.tracked);
    truth.push_back(t.truth);
    read.push_back(t.read_annotation);
    truth_annotations.push_back(t.truth_annotation);
    names.push_back("take " + std::to_string(t.take));
  }
  result.montage = montage::Compose(tracked, read, config.montage, names);
  result.montage_quality = MontageQuality(result.montage, result.takes);
  if (config.run.metrics) {
    result.truth_montage = montage::Compose(truth, truth_annotations, config.montage, names);
    result.truth_montage_quality = MontageQuality(result.truth_montage, result.takes);
  }
}

SessionRecorder& Recorder() {
  static SessionRecorder recorder = nullptr;
  return recorder;
}

}  // namespace

RunScripts::RunScripts(const RunConfig& config) : main(config.people, config.render.scene) {
  if (!config.run.practice.empty()) {
    practice.emplace(config.people, config.render.scene, config.run.practice, 0,
                     "run.practice's object");
  }
}

bool RegisterSessionRecorder(SessionRecorder recorder) {
  Recorder() = recorder;
  return true;
}

SessionRecorder RegisteredSessionRecorder() { return Recorder(); }

bool FullFidelityLinked() { return RegisteredSessionRecorder() != nullptr; }

void SetTracked(std::vector<Rigid3> poses, std::vector<track::TrackStatus> status, TakeRun& take) {
  std::vector<bool> estimated(status.size());
  for (size_t i = 0; i < status.size(); ++i) estimated[i] = status[i] != track::TrackStatus::kLost;
  if (std::count(estimated.begin(), estimated.end(), true) > 0) FillGaps(poses, estimated);
  take.tracked.poses = std::move(poses);
  take.tracked.timestamps = take.truth.timestamps;
  take.status = std::move(status);
}

std::span<const std::pair<Fidelity, const char*>> EnumNames(Fidelity) { return kFidelityNames; }

double TakeRun::EstimatedShare() const {
  if (status.empty()) return 0.0;
  const auto estimated = std::count_if(status.begin(), status.end(), [](track::TrackStatus s) {
    return s != track::TrackStatus::kLost;
  });
  return static_cast<double>(estimated) / status.size();
}

void RunOptions::Validate(const std::string& prefix) const {
  if (takes < 2) {
    ThrowBadValue(prefix + ".takes", std::to_string(takes),
                  "at least 2 takes (a montage needs two)");
  }
  if (!(min_tracked_share >= 0.0 && min_tracked_share <= 1.0)) {
    ThrowBadValue(prefix + ".min_tracked_share", FormatNumber(min_tracked_share),
                  "a share in [0, 1]");
  }
}

RunConfig RunConfig::FromConfig(const Config& config,
                                const std::vector<std::string>& extra_sections) {
  std::vector<std::string> sections = {"render",      "camera",     "scene",       "hand",
                                       "sensor",      "motion",     "scenario",    "population",
                                       "performance", "annotator",  "tracker",     "slider",
                                       "montage",     "metrics",    "error_model", "run"};
  sections.insert(sections.end(), extra_sections.begin(), extra_sections.end());
  config.RequireOnlySections(sections);
  RunConfig c;
  c.render = sim::RenderConfig::FromConfig(config);
  c.people = people::PeopleConfig::FromConfig(config);
  c.tracker = config.Get<track::ProxyTrackerOptions>("tracker");
  c.slider = config.Get<track::SliderReaderOptions>("slider");
  c.montage = config.Get<montage::ComposeOptions>("montage");
  c.metrics = config.Get<metrics::PoseErrorOptions>("metrics");
  c.error_model = config.Get<ErrorModelOptions>("error_model");
  c.run = config.Get<RunOptions>("run");
  if (c.people.scenario.story.empty()) {
    ThrowBadValue("scenario.story", "\"\"", "a story file (e.g. configs/stories/soldier.json)");
  }
  // The stories are read now, so that a missing or broken one stops the run before any output.
  [[maybe_unused]] const RunScripts scripts(c);
  // Takes the montage would refuse (no longer than the shortest segment) are refused now, before
  // anything is performed, rendered or tracked.
  const int d = c.montage.labelling.min_segment_length;
  if (c.render.render.frames > 0 && d > 0 && c.render.render.frames <= d) {
    ThrowBadValue("render.frames", std::to_string(c.render.render.frames),
                  "0 (whole takes) or more than montage.labelling.min_segment_length = " +
                      std::to_string(d) + " frames (the shortest segment a montage may take)");
  }
  if (std::abs(c.people.performance.frame_rate - c.render.sensor.frame_rate) > 1e-9) {
    ThrowBadValue("performance.frame_rate", FormatNumber(c.people.performance.frame_rate),
                  "the sensor's frame rate (sensor.frame_rate = " +
                      FormatNumber(c.render.sensor.frame_rate) + ")");
  }
  return c;
}

nlohmann::json RunConfig::ToJson() const {
  nlohmann::json j = render.ToJson();
  people.AddToJson(j);
  j["tracker"] = mmh::ToJson(tracker);
  j["slider"] = mmh::ToJson(slider);
  j["montage"] = mmh::ToJson(montage);
  j["metrics"] = mmh::ToJson(metrics);
  j["error_model"] = mmh::ToJson(error_model);
  j["run"] = mmh::ToJson(run);
  return j;
}

RunConfig RunConfig::ForAnimator(int animator) const {
  RunConfig c = *this;
  c.people.scenario.animator = animator;
  return c;
}

void FillGaps(std::vector<Rigid3>& poses, const std::vector<bool>& estimated) {
  const int n = static_cast<int>(poses.size());
  int previous = -1;
  for (int i = 0; i < n; ++i) {
    if (!estimated[i]) continue;
    if (previous < 0) {
      for (int j = 0; j < i; ++j) poses[j] = poses[i];
    } else {
      for (int j = previous + 1; j < i; ++j) {
        poses[j] = Interpolate(poses[previous], poses[i],
                               static_cast<double>(j - previous) / (i - previous));
      }
    }
    previous = i;
  }
  if (previous < 0) throw std::logic_error("FillGaps: no estimated frame");
  for (int j = previous + 1; j < n; ++j) poses[j] = poses[previous];
}

AnimatorRun RunAnimator(const RunConfig& config, const Progress& progress,
                        const TakeDone& take_done, const TakeLoader& load) {
  const auto start = Clock::now();
  AnimatorRun result;

  // Perform: the practice take, the takes, and the annotation sessions (cheap; sequential).
  auto t0 = Clock::now();
  const RunScripts scripts(config);
  result.participant = scripts.main.participant();
  std::vector<TakeRun> takes = PerformTakes(config, scripts);
  result.seconds.perform = SecondsSince(t0);
  const int practice_takes = scripts.practice ? 1 : 0;
  // Takes whose sessions an earlier run finished.
  std::vector<bool> loaded(takes.size(), false);
  if (load) {
    for (size_t slot = 0; slot < takes.size(); ++slot) {
      loaded[slot] = load(takes[slot], practice_takes && slot == 0);
    }
  }

  const ProxyModels models = LoadProxyModels(config, scripts);
  result.proxy_model = models.meshes.front();
  if (config.run.fidelity == Fidelity::kFull) {
    const SessionRecorder record = RegisteredSessionRecorder();
    if (record == nullptr) {
      throw std::logic_error(
          "RunAnimator: run.fidelity = \"full\" needs the recorded sessions, which this program "
          "does not link (mmh::pipeline_sessions, pipeline/recorded_sessions.h)");
    }
    result.rendered_frames = record(config, scripts, models, loaded, progress, takes,
                                    result.seconds);
  } else {
    t0 = Clock::now();
    const std::uint64_t seed =
        people::ParticipantSeed(config.people.population, config.people.scenario.animator);
    for (size_t slot = 0; slot < takes.size(); ++slot) {
      if (loaded[slot]) continue;
      SimulateSessions(config, seed, takes[slot]);
      if (progress) progress(slot + 1, static_cast<std::int64_t>(takes.size()));
    }
    result.seconds.record = SecondsSince(t0);
  }

  if (practice_takes) {
    result.practice = std::move(takes.front());
    takes.erase(takes.begin());
  }
  result.takes = std::move(takes);
  if (take_done) {
    if (result.practice) take_done(*result.practice, true);
    for (const TakeRun& t : result.takes) take_done(t, false);
  }
  if (result.practice) CheckTracked(*result.practice, "practice take", config.run);
  for (const TakeRun& t : result.takes) {
    CheckTracked(t, "take " + std::to_string(t.take), config.run);
  }

  t0 = Clock::now();
  ComposeMontages(config, result);
  result.seconds.compose = SecondsSince(t0);

  // metrics.json holds no timings (same config and seed, same bytes); they go to run.json.
  if (config.run.metrics) {
    t0 = Clock::now();
    result.metrics = ComputeRunMetrics(config, result, models.meshes[0],
                                       practice_takes ? &models.meshes[1] : nullptr);
    result.seconds.metrics = SecondsSince(t0);
  }
  result.seconds.total = SecondsSince(start);
  return result;
}

}  // namespace mmh::pipeline
