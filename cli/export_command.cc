// `mmh export`: a TUM trajectory plus the proxy's model as an animated glTF 2.0 binary (.glb).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "core/error.h"
#include "core/tum_io.h"
#include "report/trajectory_glb.h"

namespace mmh::cli {
namespace {

struct ExportArgs {
  std::string trajectory;
  std::string model;
  double scale = 1.0;
  std::string frame = "table";
  CommonFlags common;  // --out (a .glb file) and --quiet
};

void RunExport(const ExportArgs& args) {
  report::TrajectoryExportOptions options;
  if (args.frame == "camera") {
    options.frame = report::TrajectoryFrame::kCamera;
  } else if (args.frame != "table") {
    ThrowBadValue("--frame", args.frame, "table or camera");
  }
  if (std::filesystem::path(args.common.out_dir).extension() != ".glb") {
    ThrowBadValue("--out", args.common.out_dir, "a file name ending in .glb");
  }
  // Everything is read and checked before the file is written (atomically).
  const Trajectory trajectory = ReadTum(args.trajectory);
  options.name = std::filesystem::path(args.trajectory).stem().string();
  const TriangleMesh mesh =
      args.model.empty() ? report::OrientedStandIn() : report::LoadExportMesh(args.model, args.scale);
  report::WriteGlb(args.common.out_dir, report::TrajectoryScene(mesh, trajectory, options));
  if (!args.common.quiet) {
    std::cout << "written: " << args.common.out_dir << " (" << trajectory.size() << " keyframes, "
              << mesh.face_count() << " faces)\n";
  }
}

void AddExportCommand(CLI::App& app, const std::vector<std::string>& /*argv*/) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export", "glTF 2.0 binary (.glb) of a TUM trajectory animating the proxy's model");
  cmd->add_option("--trajectory", args->trajectory, "TUM trajectory (frame_T_proxy)")->required();
  cmd->add_option("--model", args->model,
                  "Proxy model: Duplo assembly (.json), .obj or .ply (default: an oriented stand-in)");
  cmd->add_option("--scale", args->scale, "Model scale (0.001 for millimetre models)");
  cmd->add_option("--frame", args->frame,
                  "Frame of the poses: table (z up, default) or camera (Kinect: y down, z forward)");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "", .set = false, .out_help = "Output .glb file", .threads = false});
  cmd->callback([args] { RunExport(*args); });
}

}  // namespace

MMH_REGISTER_COMMAND(85, AddExportCommand);

}  // namespace mmh::cli
