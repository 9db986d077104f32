#include "sim/sensor_check_run.h"

#include <algorithm>
#include <cstdio>
#include <iterator>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_io.h"
#include "sim/kinect_sensor.h"

namespace mmh::sim {
namespace {

// The first frame's residual correlation with the frames kTemporalLags later.
SensorCheckReport::TemporalRow TemporalStructure(const std::string& name,
                                                 const DepthSequence& sequence) {
  SensorCheckReport::TemporalRow row{name, {}};
  for (const int lag : kTemporalLags) {
    if (lag >= static_cast<int>(sequence.depth_m.size())) {
      ThrowBadValue(sequence.name + ": frames", std::to_string(sequence.depth_m.size()),
                    "at least " + std::to_string(lag + 1) + " frames (the temporal structure)");
    }
    row.lags.push_back(AnalyseTemporalCorrelation(sequence.depth_m[0], sequence.depth_m[lag],
                                                  sequence.width, sequence.height,
                                                  sequence.intrinsics));
  }
  return row;
}

// The first `frames` frames of the demo walk in one sensor mode: every frame's statistics into
// report.rendered_frames, the first frame's error structure (and, for structured light, its
// missing pixels by cause) into the report. Returns the first frame's statistics.
SensorStatistics RenderInMode(TableTopScene& table_top, const RenderConfig& config, SensorMode mode,
                            int frames, const SensorCheckOptions& options,
                            SensorCheckReport& report) {
  KinectSensorOptions sensor_options = config.sensor;
  sensor_options.mode = mode;
  const bool structured = mode == SensorMode::kStructuredLight;
  const std::string name = structured ? "rendered SL" : "rendered stat.";
  KinectSensor sensor(sensor_options, &table_top.scene(), table_top.table_T_camera());
  sensor.KeepMissingCauses(structured);
  const std::size_t first = report.rendered_frames.size();
  const int last_lag = std::end(kTemporalLags)[-1];
  std::vector<std::vector<float>> sequence;  // frames 0 .. last_lag, for the temporal structure
  PinholeIntrinsics intrinsics;
  for (int i = 0; i < std::max(frames, last_lag + 1); ++i) {
    const double t = i / config.sensor.frame_rate;
    table_top.SetFrame(config.motion.TableTProxy(t), config.motion.SliderValue(t));
    const RgbdFrame frame = sensor.Render(i);
    const int width = frame.depth_intrinsics.width;
    const int height = frame.depth_intrinsics.height;
    intrinsics = frame.depth_intrinsics;
    SensorCheckOptions frame_options = options;
    frame_options.intrinsics = frame.depth_intrinsics;
    frame_options.calibration = config.sensor.calibration;
    frame_options.noise = config.sensor.axial;
    const std::vector<float> depth_m = DepthMetresFromUnits(frame.depth, frame.depth_scale);
    if (i <= last_lag) sequence.push_back(depth_m);
    if (i >= frames) continue;
    report.rendered_frames.push_back(
        ComputeSensorStatistics(name, depth_m, width, height, frame_options));
    if (i > 0) continue;
    report.rendered_depth_m[structured ? 1 : 0] = depth_m;
    report.structure_names.push_back(name);
    report.structures.push_back(AnalyseErrorStructure(depth_m, width, height,
                                                      frame.depth_intrinsics,
                                                      config.sensor.calibration,
                                                      config.sensor.axial));
    if (structured) {
      report.cause_table = FormatCauseTable(ClassifyMissing(depth_m, width, height),
                                            sensor.missing_causes());
    }
  }
  report.temporal.push_back(TemporalStructure(
      name, {name, intrinsics.width, intrinsics.height, intrinsics, std::move(sequence)}));
  return report.rendered_frames[first];
}

}  // namespace

SensorCheckReport RunSensorCheck(const std::filesystem::path& real_frames,
                                 const RenderConfig& config, int frames,
                                 const DepthSequence* real_sequence) {
  SensorCheckReport report;
  if (real_sequence != nullptr) {
    report.temporal.push_back(TemporalStructure(real_sequence->name, *real_sequence));
  }
  const SensorCheckOptions options;
  // Real frames: TUM (5000 units per metre), NYU raw disparity, SUN (millimetres).
  const DepthImage tum = ReadDepthPng16(real_frames / "TUM_depth.png");
  report.width = tum.width;
  report.height = tum.height;
  report.tum_depth_m = DepthMetresFromUnits(tum.values, 1.0 / 5000);
  report.columns.push_back(ComputeSensorStatistics("TUM real", report.tum_depth_m, tum.width,
                                                   tum.height, options));
  const DepthImage nyu = ReadNyuRawDisparity(real_frames / "NYU_depth.pgm");
  const std::vector<float> nyu_m = DepthMetresFromNyuRaw(nyu.values);
  report.columns.push_back(ComputeSensorStatistics("NYU real", nyu_m, nyu.width, nyu.height,
                                                   options, &nyu.values));
  const DepthImage sun = ReadSunDepth(real_frames / "SUN_depth.png");
  report.columns.push_back(ComputeSensorStatistics(
      "SUN real", DepthMetresFromUnits(sun.values, 0.001), sun.width, sun.height, options));
  // The error structure of the Kinect v1 frames (SUN's sensor differs) beside the rendered ones.
  report.structure_names = {"TUM real", "NYU real"};
  report.structures = {
      AnalyseErrorStructure(report.tum_depth_m, tum.width, tum.height, options.intrinsics,
                            options.calibration, options.noise),
      AnalyseErrorStructure(nyu_m, nyu.width, nyu.height, options.intrinsics,
                            options.calibration, options.noise)};

  // Both sensor modes over the same scene.
  TableTopScene table_top(config, LoadProxyModel(config.render.proxy, config.render.proxy_scale));
  for (const SensorMode mode : {SensorMode::kStatistical, SensorMode::kStructuredLight}) {
    report.columns.push_back(RenderInMode(table_top, config, mode, frames, options, report));
  }
  return report;
}

std::string SensorCheckReport::Format() const {
  std::string text = FormatSensorTable(columns) + "\n" +
                     FormatRealismTable(structure_names, structures, 0, {2, 3}) + "\n" +
                     "structured light, first frame: " + cause_table;
  // The temporal structure: one row per sequence, rho and the windows at each lag.
  text += "\nresidual correlation with the first frame (planar windows kept in both)\n";
  char line[160];
  std::snprintf(line, sizeof(line), "%-40s", "sequence");
  text += line;
  for (const int lag : kTemporalLags) {
    std::snprintf(line, sizeof(line), "  lag %d: rho (windows)", lag);
    text += line;
  }
  text += "\n";
  for (const TemporalRow& row : temporal) {
    std::snprintf(line, sizeof(line), "%-40s", row.name.c_str());
    text += line;
    for (const TemporalCorrelation& t : row.lags) {
      std::snprintf(line, sizeof(line), "  %14.3f (%5d)", t.rho, t.patches);
      text += line;
    }
    text += "\n";
  }
  return text;
}

nlohmann::json SensorCheckReport::ToJson() const {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& c : columns) j.push_back(sim::ToJson(c));
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& c : rendered_frames) frames.push_back(sim::ToJson(c));
  nlohmann::json error_structure = nlohmann::json::object();
  for (size_t k = 0; k < structures.size(); ++k) {
    error_structure[structure_names[k]] = sim::ToJson(structures[k]);
  }
  nlohmann::json temporal_json = nlohmann::json::array();
  for (const TemporalRow& row : temporal) {
    nlohmann::json lags = nlohmann::json::array();
    for (size_t k = 0; k < row.lags.size(); ++k) {
      lags.push_back({{"lag_frames", kTemporalLags[k]},
                      {"rho", row.lags[k].rho},
                      {"windows", row.lags[k].patches}});
    }
    temporal_json.push_back({{"sequence", row.name}, {"lags", lags}});
  }
  return {{"columns", j},
          {"rendered_frames", frames},
          {"error_structure", error_structure},
          {"temporal_correlation", temporal_json}};
}

void WriteSensorCheck(const SensorCheckReport& report, const std::filesystem::path& out) {
  EnsureDirectory(out);
  WriteFileAtomically(out / "sensor_check.json", report.ToJson().dump(2) + "\n");
  // Real (TUM) and rendered depth side by side, for a look (the TUM frame is 640 x 480 too).
  if (static_cast<size_t>(report.width) * report.height == report.rendered_depth_m[0].size()) {
    WriteRgbPng(out / "sensor_check.png",
                DepthSideBySide({&report.tum_depth_m, &report.rendered_depth_m[0],
                                 &report.rendered_depth_m[1]},
                                report.width, report.height));
  }
}

}  // namespace mmh::sim
