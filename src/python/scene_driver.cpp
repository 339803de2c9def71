#include "scene_driver.h"

#include <optional>
#include <sstream>

#include "../cli/command_line.h"
#include "../cli/temperature_csv.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/report.h"
#include "collision_lab/io/scene_report.h"

namespace collision_lab {
namespace python {

namespace {

/// What collision_lab_cli's runEntry (src/cli/scene_runner.cpp) does for one scene of the
/// three lists, with the JSON report written to `out` and `cancel` for Ctrl-C.
void reportScene(const cli::CliRequest& request, io::SceneEntry entry, const std::atomic<bool>* cancel,
                 std::ostream& out) {
  if (request.restitution) entry.scene.restitution = *request.restitution;
  if (request.restitution_model) entry.scene.restitution_model = *request.restitution_model;
  if (request.ring) entry.scene.ring = *request.ring;
  const core::ScenePlan plan = core::planScene(entry.scene);
  if (const auto& error = plan.error) {
    const std::string where = entry.name.empty() ? "" : "scenario '" + entry.name + "': ";
    throw cli::CliError{core::reasonName(error->reason), static_cast<int>(error->reason), error->field,
                        where + error->message};
  }
  std::optional<cli::TemperatureCsv> temperature;  // opened before any report: a bad path is bad input
  if (request.temperature_csv) temperature.emplace(*request.temperature_csv, entry.scene);
  const core::RunOptions& shown = request.options;
  const auto three_body = io::makeThreeBodyReportWriter(io::ReportFormat::kJson, out, plan.model);
  const auto nbody = io::makeSceneReportWriter(io::ReportFormat::kJson, out);
  const bool is_three_body = plan.three_body.has_value();
  if (is_three_body) {
    three_body->begin(io::toNamedScene(entry), shown);
  } else {
    nbody->begin(entry, shown, plan.model);
  }
  core::SceneVisitors visitors;
  if (shown.events.kind != core::EventPolicy::Kind::kNone) {
    const core::EventPolicy policy = shown.events;
    visitors.three_body_event = [&, policy](const core::LabEvent& event) {
      if (policy.keeps(event.event.index)) three_body->event(event);
    };
    visitors.impact = [&, policy](const core::ImpactRecord& impact) {
      if (policy.keeps(impact.index)) nbody->impact(impact);
    };
    visitors.collapse = [&, policy](const core::Collapse& collapse) {
      if (policy.keepsAfter(collapse.impacts_before)) nbody->collapse(collapse);
    };
  }
  core::SceneRunOptions options;
  options.lab = shown;
  options.simulate_to_cap = request.simulate_to_cap;
  options.keep_events = false;  // streamed to the report, not kept
  options.cancel = cancel;
  if (temperature) {
    // As the CLI: T(t) needs every impact, the report still shows those asked for.
    visitors = temperature->feeding(std::move(visitors));
    options.lab.events = core::EventPolicy::all();
  }
  const core::SceneRunResult result = core::runScene(plan, options, visitors);
  if (temperature) temperature->finish();
  if (is_three_body) {
    three_body->end(*result.three_body);
  } else {
    nbody->end(result);
  }
}

}  // namespace

std::string runSceneJson(const std::vector<std::string>& args, const std::string& name,
                         const std::atomic<bool>* cancel) {
  std::ostringstream out;
  try {
    // No default scenario file: the module passes the three lists or --bodies only.
    const cli::CliRequest request = cli::parseCommandLine(args, "");
    if (request.action != cli::CliRequest::Action::kRunOne || !request.scene) {
      throw cli::makeCliError(cli::CliReason::kUsage, "arguments", "give the three lists or --bodies FILE");
    }
    reportScene(request, io::SceneEntry{name, "", *request.scene, 0}, cancel, out);
  } catch (const cli::CliError& error) {
    return io::jsonText(io::errorJson(error.reason, error.code, error.field, error.message));
  }
  return out.str();
}

}  // namespace python
}  // namespace collision_lab
