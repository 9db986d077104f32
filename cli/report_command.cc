// `mmh report DIR`: DIR/report.html, one self-contained page of a compose, run or study folder.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "report/html_report.h"

namespace mmh::cli {
namespace {

struct ReportArgs {
  std::string dir;
  report::ReportOptions options;
  CommonFlags common;  // --quiet
};

void AddReportCommand(CLI::App& app, const std::vector<std::string>& /*argv*/) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "report", "One self-contained HTML report (DIR/report.html) of a compose, run or study folder");
  cmd->add_option("dir", args->dir, "Output folder of mmh compose, run or study")->required();
  cmd->add_option("--dtw-image-size", args->options.dtw_image_size,
                  "Largest side of each DTW matching-cost image [cells] (default 200)");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "", .set = false, .out_help = "", .threads = false});
  cmd->callback([args] {
    const report::ReportSummary summary = report::WriteReport(args->dir, args->options);
    if (!args->common.quiet) {
      std::cout << "report (" << report::FolderKindName(summary.kind) << "): "
                << summary.file.string() << " (" << summary.bytes / 1024 << " KiB, "
                << summary.seconds * 1e3 << " ms)\n";
    }
  });
}

}  // namespace

MMH_REGISTER_COMMAND(86, AddReportCommand);

}  // namespace mmh::cli
