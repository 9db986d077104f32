#include "cli/check_paper_command.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "study/paper_audit.h"

namespace mmh::cli {
namespace {

struct CheckPaperArgs {
  std::string reported =
      (std::filesystem::path(MMH_SOURCE_DIR) / "configs" / "paper_reported.json").string();
  std::string paper;
  CommonFlags common;  // --out (optional), --quiet
};

void RunCheckPaper(const CheckPaperArgs& args, const std::vector<std::string>& argv) {
  const auto start = std::chrono::steady_clock::now();
  std::optional<std::filesystem::path> paper;
  if (!args.paper.empty()) paper = args.paper;
  const study::PaperAudit audit = study::AuditPaperFile(args.reported, paper);
  if (!args.common.out_dir.empty()) {
    const std::filesystem::path out = args.common.out_dir;
    nlohmann::json resolved = {
        {"reported", args.reported},
        {"paper", args.paper.empty() ? nlohmann::json(nullptr) : nlohmann::json(args.paper)}};
    EnsureDirectory(out);
    WriteFileAtomically(out / "paper_audit.json", audit.ToJson().dump(2) + "\n");
    WriteFileAtomically(out / "config.resolved.json", resolved.dump(2) + "\n");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    WriteFileAtomically(out / "run.json",
                        Provenance(argv, resolved, 1, {{"total", seconds}}).dump(2) + "\n");
  }
  if (!args.common.quiet) {
    std::cout << audit.Table();
    if (!args.common.out_dir.empty()) {
      std::cout << "written: " << args.common.out_dir
                << "/{paper_audit.json, config.resolved.json, run.json}\n";
    }
  }
}

}  // namespace

void AddCheckPaperCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<CheckPaperArgs>();
  CLI::App* cmd = app.add_subcommand(
      "check-paper",
      "Recompute the paper's reported p-values, t values and means (statcheck, GRIM)");
  cmd->add_option("--reported", args->reported,
                  "JSON of the reported numbers (default: configs/paper_reported.json)");
  cmd->add_option("--paper", args->paper,
                  "The paper as text: every quote is looked up in it (optional)");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "",
                  .set = false,
                  .out_help = "Output folder for paper_audit.json (optional)",
                  .out_required = false,
                  .threads = false});
  cmd->callback([args, argv] { RunCheckPaper(*args, argv); });
}

MMH_REGISTER_COMMAND(70, AddCheckPaperCommand);

}  // namespace mmh::cli
