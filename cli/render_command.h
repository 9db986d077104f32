// `mmh render` (synthetic RGB-D sequences) and `mmh sensor-check` (the sensor model's statistics
// beside those of real Kinect frames).
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh::cli {

void AddRenderCommand(CLI::App& app, const std::vector<std::string>& argv);
void AddSensorCheckCommand(CLI::App& app, const std::vector<std::string>& argv);

}  // namespace mmh::cli
