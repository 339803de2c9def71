#include "scene_runner.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <iostream>
#include <optional>

#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/scene_report.h"
#include "collision_lab/io/temperature_csv.h"
#include "progress.h"

namespace collision_lab {
namespace cli {

namespace {

std::atomic<bool> g_cancel{false};

extern "C" void onInterrupt(int) { g_cancel.store(true); }

/// SIGINT sets the cancel flag while a report is made; the previous handler (the default:
/// end the process) is back afterwards.
class InterruptGuard {
 public:
  InterruptGuard() {
    g_cancel.store(false);
    previous_ = std::signal(SIGINT, onInterrupt);
    if (previous_ == SIG_IGN) std::signal(SIGINT, SIG_IGN);  // ignored by the parent: stay so
  }
  ~InterruptGuard() { std::signal(SIGINT, previous_); }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  void (*previous_)(int) = SIG_DFL;
};

/// The scene with --restitution, --restitution-model and --ring applied.
io::SceneEntry withRequestRestitution(const CliRequest& request, io::SceneEntry entry) {
  if (request.restitution) entry.scene.restitution = *request.restitution;
  if (request.restitution_model) entry.scene.restitution_model = *request.restitution_model;
  if (request.ring) entry.scene.ring = *request.ring;
  return entry;
}

/// The entry's plan (core::planScene: validation, model, prediction, once); throws CliError
/// when the scene is rejected.
core::ScenePlan planOrThrow(const io::SceneEntry& entry) {
  core::ScenePlan plan = core::planScene(entry.scene);
  if (const auto& error = plan.error) {
    const std::string where = entry.name.empty() ? "" : "scenario '" + entry.name + "': ";
    throw CliError{core::reasonName(error->reason), static_cast<int>(error->reason), error->field,
                   where + error->message};
  }
  return plan;
}

/// The request's options, with a scene's own collision cap unless --max-collisions was given.
core::RunOptions optionsFor(const CliRequest& request, const io::SceneEntry& entry) {
  core::RunOptions options = request.options;
  if (!request.max_collisions_given && entry.max_collisions > 0) options.max_collisions = entry.max_collisions;
  return options;
}

}  // namespace

void runEntry(const CliRequest& request, const io::SceneEntry& given) {
  const InterruptGuard interrupt_guard;  // from the first byte out, so Ctrl-C never cuts a report
  const io::SceneEntry entry = withRequestRestitution(request, given);
  const core::ScenePlan plan = planOrThrow(entry);
  io::ReportedRun run;
  run.options = optionsFor(request, entry);
  run.simulate_to_cap = request.simulate_to_cap;
  run.cancel = &g_cancel;
  run.temperature_csv = request.temperature_csv;
  std::optional<ProgressLine> progress;
  // A progress line on a terminal (stderr): it only watches, so in a terminal or a pipe
  // the run takes the same path.
  if (run.options.mode != core::RunMode::kPredictOnly && isatty(STDERR_FILENO)) {
    const std::uint64_t predicted = plan.prediction && plan.prediction->impact_count ? *plan.prediction->impact_count : 0;
    progress.emplace(stderr, std::min(predicted, run.options.max_collisions));
    run.progress_interval = std::uint64_t{1} << 16;
    run.progress = [&](const core::EngineProgress& p) { progress->onEngineProgress(p.impacts, p.time); };
  }
  const auto report = io::makeSceneReportWriter(request.format, std::cout);
  try {
    io::runReported(entry, plan, run, *report);
  } catch (const io::CannotOpenFile& e) {
    throw makeCliError(CliReason::kInvalidOption, "temperature-csv", e.what());
  }
}

void runEntries(const CliRequest& request, const std::vector<io::SceneEntry>& given) {
  const InterruptGuard interrupt_guard;  // Ctrl-C cuts every remaining run short; the report is whole
  std::vector<io::SceneEntry> entries;
  for (const io::SceneEntry& entry : given) entries.push_back(withRequestRestitution(request, entry));
  std::vector<core::ScenePlan> plans;
  for (const io::SceneEntry& entry : entries) plans.push_back(planOrThrow(entry));
  std::vector<io::SceneBatchOutcome> outcomes;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const io::SceneEntry& entry = entries[i];
    const core::RunOptions options = optionsFor(request, entry);
    core::SceneRunOptions run_options;
    run_options.lab = options;  // the run keeps the events that the options ask for
    run_options.simulate_to_cap = request.simulate_to_cap;
    run_options.cancel = &g_cancel;
    outcomes.push_back({entry, options, core::runScene(plans[i], run_options)});
  }
  io::writeSceneBatchReport(request.format, outcomes, std::cout);
}

}  // namespace cli
}  // namespace collision_lab
