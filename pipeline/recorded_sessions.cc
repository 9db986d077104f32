#include "pipeline/recorded_sessions.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>

#include "sim/kinect_sensor.h"
#include "sim/props.h"
#include "track/frame_source.h"
#include "track/setup.h"
#include "track/track_session.h"

namespace mmh::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// One session to render and track: the proxy and slider per frame, and what the hand holds.
struct SessionJob {
  int take_slot = 0;  // index into the take list (the practice take first, when there is one)
  bool annotation = false;
  const TriangleMesh* model = nullptr;
  std::string model_name;
  const std::vector<TriangleMesh>* scene_objects = nullptr;  // ProxyModels::scene_objects
  sim::SessionFrames frames;
  // Results.
  track::TrackRun run;
  Rigid3 camera_T_table;  // the true one (for the ground truth in the camera frame)
  double seconds = 0.0;
};

// Renders the session frame by frame (incremental mode: only what moves is re-cast) and hands
// each frame to the tracker; nothing is stored but the tracker's results.
void RunSession(const sim::RenderConfig& render, const track::ProxyTrackerOptions& tracker,
                const track::SliderReaderOptions& slider, SessionJob& job,
                const std::function<void()>& frame_done) {
  const auto start = Clock::now();
  sim::TableTopScene scene(render, *job.model, *job.scene_objects);
  sim::KinectSensor sensor(render.sensor, &scene.scene(), scene.table_T_camera());
  job.camera_T_table = sensor.world_T_depth_camera().Inverse();
  const int frames = static_cast<int>(job.frames.table_T_proxy.size());
  track::CallbackFrameSource source(
      [&](int i, RgbdFrame* frame) {
        if (i >= frames) return false;
        scene.SetFrame(job.frames.table_T_proxy[i], job.frames.slider[i], job.frames.hand);
        sensor.Render(i, render.render.mode, frame);
        return true;
      },
      "simulated session", frames);
  track::TrackConfig config;
  config.tracker = tracker;
  config.slider = slider;
  config.track.output_frame = track::OutputFrame::kTable;
  config.track.slider = job.annotation;
  config.track.proxy = !job.annotation;
  // What the tracker is told, as a user calibrates it once before recording (scene.json holds
  // the same): the table's setup and the camera's pose above the table (the tape marks).
  const track::TrackSetup setup{render.scene, job.camera_T_table};
  job.run = track::RunTracking(source, *job.model, job.model_name, setup, true, config,
                               [&](int, int) { frame_done(); });
  job.seconds = SecondsSince(start);
}

// A recording session's results: poses in the tracker's estimated table frame.
void CollectRecording(const SessionJob& job, TakeRun& take) {
  const int frames = static_cast<int>(job.run.frames.size());
  take.camera_T_table = job.camera_T_table;
  take.estimated_camera_T_table = job.run.camera_T_table.value_or(job.camera_T_table);
  const Rigid3 table_T_camera = take.estimated_camera_T_table.Inverse();
  std::vector<Rigid3> poses(frames);
  std::vector<track::TrackStatus> status(frames);
  for (int i = 0; i < frames; ++i) {
    const track::TrackFrameResult& r = job.run.frames[i];
    status[i] = r.status;
    if (r.status != track::TrackStatus::kLost) poses[i] = table_T_camera * r.camera_T_proxy;
  }
  SetTracked(std::move(poses), std::move(status), take);
}

void CollectAnnotation(const SessionJob& job, TakeRun& take) {
  take.read_annotation = job.run.annotation;
  take.slider_found.resize(job.run.slider.size());
  for (size_t i = 0; i < job.run.slider.size(); ++i) take.slider_found[i] = job.run.slider[i].found;
}

// SessionRecorder (pipeline/recorded_sessions.h).
int RecordSessions(const RunConfig& config, const RunScripts& scripts, const ProxyModels& models,
                const std::vector<bool>& loaded, const Progress& progress,
                std::vector<TakeRun>& takes, StageSeconds& seconds) {
  // Every session is its own job (scene, sensor, tracker); jobs run in parallel and each renders
  // its frames in order, so the results do not depend on the thread count.
  const int practice_takes = scripts.practice ? 1 : 0;
  std::vector<SessionJob> jobs;
  std::int64_t total_frames = 0;
  for (size_t slot = 0; slot < takes.size(); ++slot) {
    if (loaded[slot]) continue;
    const TakeRun& t = takes[slot];
    const bool is_practice = practice_takes && slot == 0;
    const int model = is_practice ? 1 : 0;
    const int frames = static_cast<int>(t.truth.poses.size());
    const sim::StoryScript& take_script = is_practice ? *scripts.practice : scripts.main;
    SessionJob recording;
    recording.take_slot = static_cast<int>(slot);
    recording.model = &models.meshes[model];
    recording.model_name = models.names[model];
    recording.scene_objects = &models.scene_objects;
    recording.frames = take_script.RecordingFrames(t.performed, frames);
    jobs.push_back(std::move(recording));
    total_frames += frames;
    if (!is_practice) {
      SessionJob annotation;
      annotation.take_slot = static_cast<int>(slot);
      annotation.annotation = true;
      annotation.model = &models.meshes[model];
      annotation.model_name = models.names[model];
      annotation.scene_objects = &models.scene_objects;
      annotation.frames = take_script.AnnotationFrames(t.annotation, frames);
      jobs.push_back(std::move(annotation));
      total_frames += frames;
    }
  }
  // Longest jobs first (a recording frame costs about 1.6 annotation frames: the tracker's ICP
  // against the slider reader), each worker taking the next job when it is free: the greedy
  // longest-processing-time schedule keeps both cores busy to the end.
  auto cost = [&](const SessionJob& job) {
    return static_cast<double>(job.frames.table_T_proxy.size()) * (job.annotation ? 1.0 : 1.6);
  };
  std::vector<int> order(jobs.size());
  for (size_t i = 0; i < jobs.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return cost(jobs[a]) > cost(jobs[b]); });
  std::atomic<std::int64_t> done{0};
  std::mutex progress_mutex;
  auto frame_done = [&] {
    const std::int64_t d = ++done;
    if (progress && (d % 32 == 0 || d == total_frames)) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress(d, total_frames);
    }
  };
  const auto t0 = Clock::now();
  std::atomic<int> next{0};
  const int workers = std::min(static_cast<int>(jobs.size()),
                               std::max(1, tbb::this_task_arena::max_concurrency()));
  // Isolated: a thread waiting inside a job's own parallel loops (the sensor's) helps only that
  // job, instead of starting another job and leaving the first one stalled mid-frame.
  tbb::parallel_for(0, workers, 1, [&](int) {
    for (int k = next++; k < static_cast<int>(order.size()); k = next++) {
      tbb::this_task_arena::isolate([&] {
        RunSession(config.render, config.tracker, config.slider, jobs[order[k]], frame_done);
      });
    }
  });
  const double sessions_seconds = SecondsSince(t0);
  double record_cpu = 0.0, annotate_cpu = 0.0;
  for (const SessionJob& job : jobs) {
    TakeRun& t = takes[job.take_slot];
    if (job.annotation) {
      CollectAnnotation(job, t);
      annotate_cpu += job.seconds;
    } else {
      CollectRecording(job, t);
      record_cpu += job.seconds;
    }
  }
  // The sessions ran interleaved: split their wall clock in proportion to their thread time.
  const double cpu = record_cpu + annotate_cpu;
  seconds.record = cpu > 0 ? sessions_seconds * record_cpu / cpu : 0.0;
  seconds.annotate = cpu > 0 ? sessions_seconds * annotate_cpu / cpu : 0.0;
  return static_cast<int>(total_frames);
}

[[maybe_unused]] const bool kRegistered = RegisterSessionRecorder(RecordSessions);

}  // namespace
}  // namespace mmh::pipeline
