#include "sweep/slurm_backend.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"
#include "sweep/cell_store.h"
#include "sweep/local_backend.h"
#include "sweep/worker.h"

namespace mmh::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string Quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

std::string Tool(const std::string& slurm_bin, const std::string& name) {
  return slurm_bin.empty() ? name : (fs::path(slurm_bin) / name).string();
}

bool OnPath(const std::string& slurm_bin, const std::string& name) {
  if (!slurm_bin.empty()) return access(Tool(slurm_bin, name).c_str(), X_OK) == 0;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string d;
  while (std::getline(dirs, d, ':')) {
    if (!d.empty() && access((fs::path(d) / name).c_str(), X_OK) == 0) return true;
  }
  return false;
}

// Runs a shell command; its stdout (trimmed) and exit status.
std::pair<std::string, int> Capture(const std::string& command) {
  std::array<char, 512> buffer{};
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return {"", -1};
  while (fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  const int status = pclose(pipe);
  while (!output.empty() && (output.back() == '\n' || output.back() == '\r' || output.back() == ' ')) {
    output.pop_back();
  }
  return {output, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

int MaxArraySize(const Plan& plan, const SlurmSubmitOptions& options) {
  if (plan.spec.slurm.max_array_size > 0) return plan.spec.slurm.max_array_size;
  if (!options.dry_run || OnPath(options.slurm_bin, "scontrol")) {
    const auto [out, code] =
        Capture(Quote(Tool(options.slurm_bin, "scontrol")) + " show config 2>/dev/null");
    std::stringstream lines(out);
    std::string line;
    while (std::getline(lines, line)) {
      if (line.rfind("MaxArraySize", 0) == 0) {
        const std::size_t eq = line.find('=');
        if (eq != std::string::npos) return std::max(2, std::atoi(line.c_str() + eq + 1));
      }
    }
  }
  return 1001;  // Slurm's default
}

fs::path ManifestPath(const fs::path& dir) { return dir / "slurm" / "manifest.json"; }

json ReadManifest(const fs::path& dir) {
  const fs::path file = ManifestPath(dir);
  if (!fs::exists(file)) {
    ThrowBadValue(file.string(), "missing", "the manifest of a Slurm sweep (mmh sweep --backend slurm)");
  }
  // As plan.json (sweep/plan.cc): ParseJsonText with ReadTextFile's 1 GiB cap.
  const json j = ParseJsonText(ReadTextFile(file), file.string());
  if (!j.contains("tasks")) {
    ThrowBadValue(file.string(), "unreadable", "the manifest mmh sweep wrote");
  }
  return j;
}

// Per chunk of the tasks (array indices 0..max-1), the indices with missing or failed cells.
std::vector<std::vector<int>> IncompleteByChunk(const Plan& plan, const fs::path& dir,
                                                const json& manifest) {
  const int max = manifest.at("max_array_size").get<int>();
  const auto& tasks = manifest.at("tasks");
  std::vector<std::vector<int>> chunks((tasks.size() + max - 1) / max);
  for (std::size_t t = 0; t < tasks.size(); ++t) {
    bool incomplete = false;
    for (const auto& c : tasks[t]) {
      incomplete = incomplete ||
                   ReadCellStatus(dir, plan.cells[c.get<int>()].id).state != CellState::kComplete;
    }
    if (incomplete) chunks[t / max].push_back(static_cast<int>(t % max));
  }
  return chunks;
}

}  // namespace

std::string ArrayRanges(const std::vector<int>& indices) {
  std::vector<int> v = indices;
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  std::string out;
  for (std::size_t i = 0; i < v.size();) {
    std::size_t j = i;
    while (j + 1 < v.size() && v[j + 1] == v[j] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(v[i]);
    if (j > i) out += "-" + std::to_string(v[j]);
    i = j + 1;
  }
  return out;
}

void RequireSlurm(const std::string& slurm_bin, bool dry_run) {
  if (dry_run || OnPath(slurm_bin, "sbatch")) return;
  const char* path = std::getenv("PATH");
  ThrowBadValue(slurm_bin.empty() ? "--backend slurm: PATH" : "--slurm-bin",
                slurm_bin.empty() ? std::string(path ? path : "") : slurm_bin,
                "a folder with Slurm's sbatch (on a cluster's login node; or --dry-run to write "
                "the job script only)");
}

std::vector<int> TaskCells(const fs::path& dir, int task) {
  const json manifest = ReadManifest(dir);
  const auto& tasks = manifest.at("tasks");
  if (task < 0 || task >= static_cast<int>(tasks.size())) {
    ThrowBadValue("--task", std::to_string(task),
                  "a task of " + ManifestPath(dir).string() + " (0.." +
                      std::to_string(tasks.size() - 1) + ")");
  }
  return tasks[task].get<std::vector<int>>();
}

SlurmSubmission SubmitSlurm(const Plan& plan, const fs::path& dir,
                            const SlurmSubmitOptions& options) {
  SlurmSubmission s;
  const SlurmOptions& slurm = plan.spec.slurm;
  const int threads = std::max(1, options.threads);
  EnsureDirectory(dir / "slurm");
  EnsureDirectory(dir / "logs");
  // The manifest is written once: the task numbers must stay those of earlier submissions.
  json manifest;
  if (fs::exists(ManifestPath(dir))) {
    manifest = ReadManifest(dir);
  } else {
    const int n = static_cast<int>(plan.cells.size());
    int per_task = slurm.cells_per_task > 0 ? slurm.cells_per_task : plan.cells_per_worker;
    if (per_task <= 0) per_task = AutoCellsPerWorker(n, 16);
    json tasks = json::array();
    for (const auto& t : PackCells(n, per_task)) tasks.push_back(t);
    manifest = {{"cells_per_task", per_task},
                {"max_array_size", MaxArraySize(plan, options)},
                {"tasks", tasks},
                {"cells", [&] {
                   json ids = json::array();
                   for (const auto& c : plan.cells) ids.push_back(c.id);
                   return ids;
                 }()}};
    WriteFileAtomically(ManifestPath(dir), manifest.dump(1) + "\n");
  }

  std::string header = "#!/bin/bash\n";
  if (!slurm.partition.empty()) header += "#SBATCH --partition=" + slurm.partition + "\n";
  if (!slurm.time_limit.empty()) header += "#SBATCH --time=" + slurm.time_limit + "\n";
  for (const auto& a : slurm.sbatch_args) header += "#SBATCH " + a + "\n";
  const std::string array_script =
      header + "#SBATCH --job-name=mmh-sweep\n#SBATCH --cpus-per-task=" + std::to_string(threads) +
      "\n#SBATCH --output=" + (dir / "logs" / "task_%A_%a.log").string() +
      "\n#SBATCH --open-mode=append\n#SBATCH --requeue\n"
      "# One task of the sweep in " + dir.string() + " (slurm/manifest.json): the worker skips\n"
      "# the task's complete cells, so a requeued task redoes only what did not finish.\n"
      "set -eu\n"
      "task=$(( ${MMH_SWEEP_TASK_OFFSET:-0} + SLURM_ARRAY_TASK_ID ))\n"
      "exec " + Quote(options.executable) + " sweep worker " + Quote(dir.string()) +
      " --task \"$task\" --threads " + std::to_string(threads) + "\n";
  const std::string aggregate_script =
      header + "#SBATCH --job-name=mmh-sweep-aggregate\n#SBATCH --cpus-per-task=1\n#SBATCH --output=" +
      (dir / "logs" / "aggregate_%j.log").string() +
      "\n#SBATCH --open-mode=append\nset -eu\nexec " + Quote(options.executable) +
      " sweep aggregate " + Quote(dir.string()) + "\n";
  const fs::path array_file = dir / "slurm" / "array.sh";
  const fs::path aggregate_file = dir / "slurm" / "aggregate.sh";
  WriteFileAtomically(array_file, array_script);
  WriteFileAtomically(aggregate_file, aggregate_script);
  fs::permissions(array_file, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
  fs::permissions(aggregate_file, fs::perms::owner_exec | fs::perms::group_exec,
                  fs::perm_options::add);

  const int max = manifest.at("max_array_size").get<int>();
  const auto chunks = IncompleteByChunk(plan, dir, manifest);
  std::string message = "sweep: " + std::to_string(plan.cells.size()) + " cells in " +
                        std::to_string(manifest["tasks"].size()) + " tasks of up to " +
                        std::to_string(manifest["cells_per_task"].get<int>()) +
                        " cells; scripts in " + (dir / "slurm").string() + "\n";
  const std::string sbatch = Quote(Tool(options.slurm_bin, "sbatch"));
  json record = json::array();
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    if (chunks[k].empty()) continue;
    s.tasks_submitted += static_cast<int>(chunks[k].size());
    std::string array = ArrayRanges(chunks[k]);
    if (slurm.throttle > 0) array += "%" + std::to_string(slurm.throttle);
    const std::string command = sbatch + " --parsable --array=" + array +
                                " --export=ALL,MMH_SWEEP_TASK_OFFSET=" +
                                std::to_string(k * max) + " " + Quote(array_file.string());
    if (options.dry_run) {
      message += "would run: " + command + "\n";
      continue;
    }
    const auto [out, code] = Capture(command + " 2>&1");
    if (code != 0) throw std::runtime_error("sbatch failed (" + command + "): " + out);
    const std::string id = out.substr(0, out.find(';'));
    s.array_job_ids.push_back(id);
    record.push_back({{"job_id", id}, {"array", array}, {"offset", k * max}});
    message += "submitted array job " + id + " (--array=" + array + ", tasks from " +
               std::to_string(k * max) + ")\n";
  }
  if (s.tasks_submitted == 0) {
    message += "every cell is complete: nothing to submit (mmh sweep aggregate " + dir.string() +
               " gathers the results)\n";
    return s.message = message, s;
  }
  std::string dependency;
  for (const auto& id : s.array_job_ids) dependency += ":" + id;
  const std::string aggregate_command =
      sbatch + " --parsable" + (dependency.empty() ? "" : " --dependency=afterany" + dependency) +
      " " + Quote(aggregate_file.string());
  if (options.dry_run) {
    message += "would run: " + aggregate_command + "\n";
  } else {
    const auto [out, code] = Capture(aggregate_command + " 2>&1");
    if (code != 0) throw std::runtime_error("sbatch failed (" + aggregate_command + "): " + out);
    s.aggregate_job_id = out.substr(0, out.find(';'));
    message += "submitted the aggregation as job " + s.aggregate_job_id +
               " (after the arrays end)\n";
    json history = json::array();
    const fs::path history_file = dir / "slurm" / "submissions.json";
    if (fs::exists(history_file)) {
      // Read after the jobs were submitted: a damaged history is started again rather than
      // failing a submission that has happened.
      try {
        history = ReadJsonFile(history_file);
      } catch (const InputError&) {
      }
      if (!history.is_array()) history = json::array();
    }
    history.push_back({{"arrays", record}, {"aggregate_job_id", s.aggregate_job_id}});
    WriteFileAtomically(history_file, history.dump(1) + "\n");
  }
  s.message = message;
  return s;
}

std::string StatusReport(const Plan& plan, const fs::path& dir) {
  int done = 0, failed = 0, missing = 0, running = 0;
  std::string failures;
  for (const auto& cell : plan.cells) {
    const CellStatus status = ReadCellStatus(dir, cell.id);
    switch (status.state) {
      case CellState::kComplete: ++done; break;
      case CellState::kFailed: {
        ++failed;
        std::string last = status.stderr_tail.substr(status.stderr_tail.rfind('\n') + 1);
        failures += "  failed " + cell.id + " (point " + std::to_string(cell.point) +
                    ", replicate " + std::to_string(cell.replicate) + "): " + last + "\n";
        break;
      }
      case CellState::kMissing:
        ++missing;
        if (!TempCellDirs(dir, cell.id).empty()) ++running;
        break;
    }
  }
  std::string report = "sweep " + dir.string() + ": " + std::to_string(plan.cells.size()) +
                       " cells: " + std::to_string(done) + " done, " + std::to_string(failed) +
                       " failed, " + std::to_string(missing) + " missing" +
                       (running ? " (" + std::to_string(running) + " in progress or interrupted)"
                                : "") +
                       "\n" + failures;
  if (fs::exists(ManifestPath(dir))) {
    const json manifest = ReadManifest(dir);
    const auto chunks = IncompleteByChunk(plan, dir, manifest);
    const int max = manifest.at("max_array_size").get<int>();
    for (std::size_t k = 0; k < chunks.size(); ++k) {
      if (chunks[k].empty()) continue;
      report += "resubmit: sbatch --array=" + ArrayRanges(chunks[k]) +
                " --export=ALL,MMH_SWEEP_TASK_OFFSET=" + std::to_string(k * max) + " " +
                (dir / "slurm" / "array.sh").string() + "\n";
    }
  }
  return report;
}

}  // namespace mmh::sweep
