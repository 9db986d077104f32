#include "cli/common_flags.h"

#include <tbb/global_control.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>

#include "cli/provenance.h"
#include "core/config.h"
#include "core/duration_text.h"

namespace mmh::cli {

void AddCommonFlags(CLI::App* command, CommonFlags* flags, const CommonFlagsSpec& spec) {
  if (!spec.config_help.empty()) {
    CLI::Option* config = command->add_option("--config", flags->config_file, spec.config_help);
    if (spec.config_required) config->required();
  }
  if (spec.set) {
    command->add_option("--set", flags->sets, spec.set_help)->take_all();
  }
  if (!spec.out_help.empty()) {
    CLI::Option* out = command->add_option("--out", flags->out_dir, spec.out_help);
    if (spec.out_required) out->required();
  }
  if (spec.threads) {
    command->add_option("--threads", flags->threads, spec.threads_help)
        ->check(CLI::NonNegativeNumber);
  }
  if (spec.quiet) command->add_flag("--quiet", flags->quiet, "Print nothing on success");
}

Config LoadConfig(const CommonFlags& common) {
  // run.json's git_commit is the commit checked out when the command starts: asked at the end, a
  // 45-minute study named a commit made while it ran.
  StartGitCommitLookup();
  Config config;
  if (!common.config_file.empty()) config = Config::Load(common.config_file);
  for (const auto& set : common.sets) config.Set(set);
  return config;
}

std::shared_ptr<void> LimitThreads(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               threads);
}

bool ShowProgress(const CommonFlags& common) { return !common.quiet && isatty(STDERR_FILENO); }

ProgressBar::ProgressBar(bool enabled, std::string label, std::string unit)
    : enabled_(enabled), label_(std::move(label)), unit_(std::move(unit)) {}

void ProgressBar::Update(std::int64_t done, std::int64_t total) {
  if (!enabled_) return;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = seconds > 0 ? done / seconds : 0.0;
  if (total <= 0) {
    std::fprintf(stderr, "\r%s: %lld %s, %.0f %s/s ", label_.c_str(),
                 static_cast<long long>(done), unit_.c_str(), rate, unit_.c_str());
    open_line_ = true;
    std::fflush(stderr);
    return;
  }
  const int width = 30;
  const int filled = static_cast<int>(width * std::min(done, total) / total);
  const std::string left =
      done > 0 && done < total ? ", " + FormatDuration(seconds / done * (total - done)) + " left"
                               : std::string();
  std::fprintf(stderr, "\r%s [%s%s] %lld / %lld %s, %.0f %s/s%s ", label_.c_str(),
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
               static_cast<long long>(done), static_cast<long long>(total), unit_.c_str(), rate,
               unit_.c_str(), left.c_str());
  open_line_ = done < total;
  if (done >= total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

void ProgressBar::Finish() {
  if (!open_line_) return;
  std::fprintf(stderr, "\n");
  std::fflush(stderr);
  open_line_ = false;
}

}  // namespace mmh::cli
