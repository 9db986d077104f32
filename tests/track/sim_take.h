// A simulated take for the tracker's tests and benchmark: the renderer's table-top scene with the
// Soldier proxy, the hand and the slider block, rendered by the Kinect model in memory, with the
// ground truth beside each frame. Only tests and benchmarks use sim/; track/ never does.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/config.h"
#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"
#include "sim/kinect_sensor.h"
#include "people/performance.h"
#include "people/population.h"
#include "sim/render_session.h"
#include "sim/session_script.h"
#include "people/story.h"
#include "track/setup.h"
#include "tests/statistical_frames.h"

namespace mmh::track::test_take {

// The frames the tracker's unit tests were written against (test_util::StatisticalFrameSettings:
// the statistical sensor at 1.17 m). The tests' thresholds are about the tracker's algorithms on
// frames with the statistical model's errors; structured-light frames have tests of their own.
inline void UseStatisticalFrames(Config* config) {
  for (const std::string& s : test_util::StatisticalFrameSettings()) config->Set(s);
}
inline sim::RenderConfig StatisticalConfig() {
  Config config;
  UseStatisticalFrames(&config);
  return sim::RenderConfig::FromConfig(config);
}

class SimTake {
 public:
  // table_T_proxy(t) and slider(t) drive the proxy and the block; empty: the demo walk and sweep
  // of config.motion.
  explicit SimTake(sim::RenderConfig config = StatisticalConfig(),
                   std::function<Rigid3(double)> table_T_proxy = {},
                   std::function<double(double)> slider = {})
      : config_(std::move(config)),
        table_T_proxy_(std::move(table_T_proxy)),
        slider_(std::move(slider)) {
    model_ = sim::LoadProxyModel(config_.render.proxy, config_.render.proxy_scale);
    scene_ = std::make_unique<sim::TableTopScene>(config_, model_);
    sensor_ = std::make_unique<sim::KinectSensor>(config_.sensor, &scene_->scene(),
                                                  scene_->table_T_camera());
    depth_T_table_ = sensor_->world_T_depth_camera().Inverse();
  }

  // Renders frame i; the true camera_T_proxy and slider value when asked.
  RgbdFrame Render(int i, Rigid3* camera_T_proxy = nullptr, double* slider_value = nullptr) {
    const double t = i / config_.sensor.frame_rate;
    const Rigid3 table_T_proxy = table_T_proxy_ ? table_T_proxy_(t) : config_.motion.TableTProxy(t);
    const double slider = slider_ ? slider_(t) : config_.motion.SliderValue(t);
    scene_->SetFrame(table_T_proxy, slider, hand_);
    if (camera_T_proxy) *camera_T_proxy = depth_T_table_ * table_T_proxy;
    if (slider_value) *slider_value = slider;
    return sensor_->Render(i);
  }

  // The setup calibration a user would mark once (as scene.json holds it).
  TrackSetup Setup() const { return TrackSetup{config_.scene, depth_T_table_}; }

  const TriangleMesh& model() const { return model_; }
  const Rigid3& depth_T_table() const { return depth_T_table_; }
  const sim::RenderConfig& config() const { return config_; }
  // Which object the hand holds: the proxy (recording) or the slider block (annotation session).
  void set_hand(sim::TableTopScene::Hand hand) { hand_ = hand; }

 private:
  sim::RenderConfig config_;
  sim::TableTopScene::Hand hand_ = sim::TableTopScene::Hand::kOnProxy;
  std::function<Rigid3(double)> table_T_proxy_;
  std::function<double(double)> slider_;
  TriangleMesh model_;
  std::unique_ptr<sim::TableTopScene> scene_;
  std::unique_ptr<sim::KinectSensor> sensor_;
  Rigid3 depth_T_table_;
};

// A session of the Soldier story (configs/study_soldier.json: the castle props, the study's
// population) as `mmh render --config configs/study_soldier.json --set scenario.animator=A
// --set render.take=K --set render.session=...` renders it: participant `animator` performs take
// `take` of the Soldier (people::PerformTake); a recording session moves the proxy along the performed
// take with the hand on it, an annotation session rests the proxy beside the play area and moves
// the slider block as the participant annotates the take. *frames: the take's length.
// `source` is the project's folder (MMH_SOURCE_DIR).
// `config_file` (relative to `source`) may name another story's config (configs/mario.json).
// statistical: the frames of UseStatisticalFrames (else the sensor and camera the config gives).
inline SimTake SoldierStorySession(const std::string& source, int animator, int take,
                                   sim::RenderSession session, int* frames,
                                   const std::string& config_file = "configs/study_soldier.json",
                                   bool statistical = true) {
  Config file = Config::Load(source + "/" + config_file);
  if (statistical) UseStatisticalFrames(&file);
  sim::RenderConfig config = sim::RenderConfig::FromConfig(file);
  people::PeopleConfig people = people::PeopleConfig::FromConfig(file);
  // The people the tests' takes and their events were measured with, unless the config sets them:
  // the learning and the annotators' dead band of configs/people/calibrated_2026_11_25.json (the
  // recalibration of 2026-11-29 changed them, and with them every performed take).
  const people::PeopleConfig measured_with = people::PeopleConfig::FromConfig(
      Config::Load(source + "/configs/people/calibrated_2026_11_25.json"));
  const nlohmann::json& root = file.root();
  const bool has_population = root.contains("population") && root["population"].is_object();
  if (!has_population || !root["population"].contains("learning_mean")) {
    people.population.learning_mean = measured_with.population.learning_mean;
  }
  if (!has_population || !root["population"].contains("move_threshold_mean")) {
    people.population.move_threshold_mean = measured_with.population.move_threshold_mean;
  }
  people.scenario.story = source + "/" + people.scenario.story;
  people.scenario.animator = animator;
  config.render.take = take;
  config.render.session = session;
  const sim::StoryScript script(people, config.scene);
  auto performed = std::make_shared<const people::PerformedTake>(script.Perform(take));
  config.render.proxy = script.ProxyFile();
  *frames = performed->frames();
  const double rate = config.sensor.frame_rate;
  const int last = *frames - 1;
  auto frame_at = [rate, last](double t) {
    return std::clamp(static_cast<int>(std::lround(t * rate)), 0, last);
  };
  if (session == sim::RenderSession::kRecording) {
    const double rest = people.annotator.start_value;
    return SimTake(
        config,
        [performed, frame_at](double t) { return performed->table_T_proxy.poses[frame_at(t)]; },
        [rest](double) { return rest; });
  }
  auto slider = std::make_shared<const std::vector<double>>(script.Annotate(*performed).slider);
  SimTake annotation(
      config, [](double) { return sim::RestingTableTProxy(); },
      [slider, frame_at](double t) { return (*slider)[frame_at(t)]; });
  annotation.set_hand(sim::TableTopScene::Hand::kOnSlider);
  return annotation;
}

}  // namespace mmh::track::test_take
