#include "sweep/worker.h"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/atomic_file.h"
#include "core/error.h"
#include "sweep/cell_store.h"

namespace mmh::sweep {
namespace {

namespace fs = std::filesystem;

// "kill" or "fail" when MMH_SWEEP_FAULT names this cell, else "".
std::string InjectedFault(const std::string& id) {
  const char* env = std::getenv("MMH_SWEEP_FAULT");
  if (!env) return "";
  const std::string faults = env;
  for (const std::string kind : {"kill", "fail", "sleep"}) {
    if (faults.find(kind + ":" + id) != std::string::npos) return kind;
  }
  return "";
}

// Sends this process's stdout and stderr to `file` while it lives.
class RedirectOutput {
 public:
  explicit RedirectOutput(const fs::path& file) {
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    const int fd = open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error(file.string() + ": cannot be written");
    saved_out_ = dup(STDOUT_FILENO);
    saved_err_ = dup(STDERR_FILENO);
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    close(fd);
  }
  ~RedirectOutput() {
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    dup2(saved_out_, STDOUT_FILENO);
    dup2(saved_err_, STDERR_FILENO);
    close(saved_out_);
    close(saved_err_);
  }
  RedirectOutput(const RedirectOutput&) = delete;
  RedirectOutput& operator=(const RedirectOutput&) = delete;

 private:
  int saved_out_ = -1;
  int saved_err_ = -1;
};

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return stamp;
}

}  // namespace

std::vector<std::string> CellArguments(const Plan& plan, const fs::path& dir, const Cell& cell,
                                       const fs::path& out, int threads) {
  std::vector<std::string> argv = {"mmh", CommandName(plan.spec.command)};
  argv.insert(argv.end(), plan.inputs.begin(), plan.inputs.end());
  argv.insert(argv.end(), {"--config", CellConfigPath(dir, cell).string(), "--out", out.string(),
                           "--threads", std::to_string(threads), "--quiet"});
  return argv;
}

std::vector<std::vector<int>> PackCells(int cells, int per_task) {
  std::vector<std::vector<int>> tasks;
  per_task = std::max(1, per_task);
  for (int i = 0; i < cells; ++i) {
    if (i % per_task == 0) tasks.emplace_back();
    tasks.back().push_back(i);
  }
  return tasks;
}

int RunWorker(const Plan& plan, const fs::path& dir, const std::vector<int>& cells,
              const WorkerOptions& options, const CommandRunner& runner) {
  // The cells' relative paths (takes, stories) are relative to where the sweep was started.
  if (chdir(plan.workdir.c_str()) != 0) {
    throw InputError(plan.workdir.string() + ": the sweep's working folder cannot be entered");
  }
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  int failed = 0;
  for (int index : cells) {
    if (index < 0 || index >= static_cast<int>(plan.cells.size())) {
      ThrowBadValue("cell index", std::to_string(index),
                    "an index below " + std::to_string(plan.cells.size()));
    }
    const Cell& cell = plan.cells[index];
    if (ReadCellStatus(dir, cell.id).state == CellState::kComplete) continue;
    ClearCellForRerun(dir, cell.id);
    const fs::path temp = NewTempCellDir(dir, cell.id);
    const std::vector<std::string> argv =
        CellArguments(plan, dir, cell, temp / "out", options.threads);
    const auto start = std::chrono::steady_clock::now();
    int code = 0;
    {
      RedirectOutput redirect(temp / "output.txt");
      const std::string fault = InjectedFault(cell.id);
      if (fault == "kill") std::raise(SIGKILL);
      // A cell slow enough for a test to preempt (scontrol requeue) while it runs.
      if (fault == "sleep") std::this_thread::sleep_for(std::chrono::seconds(8));
      if (fault == "fail") {
        std::cerr << "mmh: failed: injected failure (MMH_SWEEP_FAULT)\n";
        code = 1;
      } else {
        code = runner(argv);
      }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    CellStatus status;
    status.exit_code = code;
    status.stderr_tail = code == 0 ? "" : TailOfFile(temp / "output.txt");
    WriteStatus(temp, status);
    WriteFileAtomically(temp / "provenance.json",
                        nlohmann::json{{"backend", options.backend},
                                       {"host", host},
                                       {"pid", static_cast<int>(getpid())},
                                       {"threads", options.threads},
                                       {"seconds", seconds},
                                       {"finished_utc", UtcNow()},
                                       {"command", argv}}
                                .dump(2) +
                            "\n");
    PublishCell(dir, cell.id, temp);
    if (code != 0) ++failed;
  }
  return failed;
}

}  // namespace mmh::sweep
