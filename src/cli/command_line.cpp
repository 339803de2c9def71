#include "command_line.h"

#include <algorithm>
#include <array>

#include <CLI/CLI.hpp>

#include "collision_lab/io/bodies_csv.h"
#include "collision_lab/io/number_text.h"

namespace collision_lab {
namespace cli {

namespace {

/// Options that take a value. A value may start with '-' (negative numbers, "-inf",
/// "-.5"), which CLI11 would take for a flag; normalizeArguments() prevents that.
const std::array<const char*, 19> kValueOptions = {
    "--masses", "--positions", "--velocities", "--bodies",   "--restitution", "--max-collisions",
    "--restitution-model", "--tc", "--elastic-below", "--viscoelastic-speed", "--ring",
    "--events", "--format",    "--precision",  "--mode",     "--scenario",    "--name",
    "--temperature-csv", "--full-state-every"};

bool isValueOption(const std::string& arg) {
  return std::find(kValueOptions.begin(), kValueOptions.end(), arg) != kValueOptions.end();
}

CliError missingValue(const std::string& option) {
  return makeCliError(CliReason::kMissingInput, option.substr(2), "the option is given without a value");
}

/// "--velocities -1,0,0" -> "--velocities=-1,0,0": a value option takes the next
/// argument as its value, as getopt does. A value option that is last, or followed by
/// another long option, or written "--masses=", has no value (CLI11 would take the next
/// argument, even "--format=json", as the value).
std::vector<std::string> normalizeArguments(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg.size() > 1 && arg.back() == '=' && isValueOption(arg.substr(0, arg.size() - 1))) {
      throw missingValue(arg.substr(0, arg.size() - 1));
    }
    if (!isValueOption(arg)) {
      out.push_back(arg);
      continue;
    }
    if (i + 1 == args.size() || args[i + 1].rfind("--", 0) == 0) throw missingValue(arg);
    out.push_back(arg + "=" + args[i + 1]);
    ++i;
  }
  return out;
}

/// CLI11 and YAML messages may span lines; the CLI promises one line.
std::string oneLine(std::string text) {
  std::replace_if(text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

/// "1,2,inf" -> its doubles, any number of them; `field` is "masses", "positions",
/// "velocities" or "restitution". Messages do not repeat the field, which the error line
/// names already.
std::vector<double> parseList(const std::string& text, const std::string& field) {
  const std::vector<std::string> items = io::splitCommaList(text);
  std::vector<double> values;
  values.reserve(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    const io::ParsedNumber parsed = io::parseNumber(items[i]);
    if (!parsed.problem.empty()) {
      throw makeCliError(CliReason::kMalformedNumber, field + "[" + std::to_string(i) + "]",
                         "'" + items[i] + "' " + parsed.problem);
    }
    values.push_back(parsed.value);
  }
  return values;
}

/// The bodies of --bodies FILE ("-": standard input).
core::Scene readBodies(const std::string& path) {
  try {
    return io::readBodiesFile(path);
  } catch (const io::BodiesFileError& e) {
    switch (e.kind) {
      case io::BodiesFileError::Kind::kWrongCount: throw makeCliError(CliReason::kWrongCount, e.field, e.what());
      case io::BodiesFileError::Kind::kMalformedNumber:
        throw makeCliError(CliReason::kMalformedNumber, e.field, e.what());
      case io::BodiesFileError::Kind::kUnreadable:
      case io::BodiesFileError::Kind::kHeader: break;
    }
    throw makeCliError(CliReason::kBodiesFile, e.field, e.what());
  }
}

/// The options as typed, before their values are checked.
struct RawOptions {
  std::string masses, positions, velocities, bodies, restitution;
  std::string restitution_model, tc, elastic_below, viscoelastic_speed, ring;
  std::string max_collisions, events, format = "table", precision, mode = "full";
  std::string scenario, name, temperature_csv, full_state_every;
  bool list = false;
  bool simulate_to_cap = false;
  bool masses_given = false, positions_given = false, velocities_given = false, bodies_given = false;
  bool restitution_given = false;
  bool max_collisions_given = false, events_given = false, scenario_given = false, name_given = false;
  bool temperature_csv_given = false;
  bool precision_given = false;
  bool full_state_every_given = false;
};

/// Format, mode and collision cap; --precision, removed, is refused.
void readRunOptions(const RawOptions& raw, CliRequest& request) {
  const auto format = io::parseReportFormat(raw.format);
  if (!format) {
    throw makeCliError(CliReason::kInvalidOption, "format", "'" + raw.format + "' is not table, json or csv");
  }
  request.format = *format;
  if (raw.precision_given) {
    throw makeCliError(CliReason::kInvalidOption, "precision",
                       "--precision was removed: every run is exact (the event engine decides every impact as exact "
                       "rational arithmetic would and rounds its values once), so there is no working precision to "
                       "choose; drop the option");
  }
  const auto mode = io::parseRunMode(raw.mode);
  if (!mode) {
    throw makeCliError(CliReason::kInvalidOption, "mode", "'" + raw.mode + "' is not full, predict or summary");
  }
  request.options.mode = *mode;
  request.simulate_to_cap = raw.simulate_to_cap;
  if (raw.max_collisions_given) {
    const io::ParsedCount cap = io::parseCount(raw.max_collisions);
    if (!cap.problem.empty()) {
      throw makeCliError(CliReason::kInvalidOption, "max-collisions", "'" + raw.max_collisions + "' " + cap.problem);
    }
    request.options.max_collisions = cap.value;
    request.max_collisions_given = true;
  }
}

/// What to run: a scene from the three lists, or one scene, all scenes or the list of a file.
void readSceneSource(const RawOptions& raw, const std::string& default_scenario_path, CliRequest& request) {
  const bool any_list = raw.masses_given || raw.positions_given || raw.velocities_given;
  const bool from_file = raw.scenario_given || raw.name_given || raw.list;
  if ((any_list || raw.bodies_given) && from_file) {
    throw makeCliError(CliReason::kUsage, "scenario",
                       "give either --masses/--positions/--velocities or --scenario/--name/--list, not both");
  }
  if (any_list && raw.bodies_given) {
    throw makeCliError(CliReason::kUsage, "bodies",
                       "give either --bodies FILE or --masses/--positions/--velocities, not both");
  }
  if (from_file) {
    request.scenario_path = raw.scenario_given ? raw.scenario : default_scenario_path;
    if (raw.list) {
      request.action = CliRequest::Action::kList;
    } else if (raw.name_given) {
      request.action = CliRequest::Action::kRunOne;
      request.scenario_name = raw.name;
    } else {
      request.action = CliRequest::Action::kRunAll;
    }
    return;
  }
  request.action = CliRequest::Action::kRunOne;
  if (raw.bodies_given) {
    request.scene = readBodies(raw.bodies);
    return;
  }
  for (const auto& [given, field] : {std::pair{raw.masses_given, "masses"}, std::pair{raw.positions_given, "positions"},
                                     std::pair{raw.velocities_given, "velocities"}}) {
    if (!given) {
      throw makeCliError(CliReason::kMissingInput, field,
                         "missing: give --masses, --positions and --velocities (one comma-separated number per "
                         "body each), or --bodies FILE, or --scenario FILE");
    }
  }
  core::Scene scene;
  scene.masses = parseList(raw.masses, "masses");
  scene.positions = parseList(raw.positions, "positions");
  scene.velocities = parseList(raw.velocities, "velocities");
  request.scene = std::move(scene);
}

/// One number of an option, e.g. --tc 1e-3.
double parseOne(const std::string& text, const std::string& field) {
  const std::vector<double> values = parseList(text, field);
  if (values.size() != 1) throw makeCliError(CliReason::kInvalidOption, field, "'" + text + "' is not one number");
  return values[0];
}

/// --restitution-model and its parameter, and --ring. A parameter needs its model; the
/// model's parameter is checked by the core's validation (RESTITUTION_MODEL).
void readSceneOptions(const CLI::App& app, const RawOptions& raw, CliRequest& request) {
  struct Parameter {
    const char* option;
    const std::string& text;
    core::RestitutionModelKind kind;
  };
  const Parameter parameters[] = {{"--tc", raw.tc, core::RestitutionModelKind::kTc},
                                  {"--elastic-below", raw.elastic_below, core::RestitutionModelKind::kThreshold},
                                  {"--viscoelastic-speed", raw.viscoelastic_speed, core::RestitutionModelKind::kViscoelastic}};
  if (app.count("--restitution-model") > 0) {
    core::RestitutionModel model;
    const std::string& name = raw.restitution_model;
    bool known = false;
    for (auto kind : {core::RestitutionModelKind::kConstant, core::RestitutionModelKind::kTc,
                      core::RestitutionModelKind::kThreshold, core::RestitutionModelKind::kViscoelastic}) {
      if (name == core::restitutionModelName(kind)) model.kind = kind, known = true;
    }
    if (!known) {
      throw makeCliError(CliReason::kInvalidOption, "restitution-model",
                         "'" + name + "' is not constant, tc, threshold or viscoelastic");
    }
    request.restitution_model = model;
  }
  for (const Parameter& parameter : parameters) {
    if (app.count(parameter.option) == 0) continue;
    const std::string field = std::string(parameter.option).substr(2);
    if (!request.restitution_model || request.restitution_model->kind != parameter.kind) {
      throw makeCliError(CliReason::kUsage, field,
                         std::string(parameter.option) + " belongs to --restitution-model " +
                             core::restitutionModelName(parameter.kind));
    }
    const double value = parseOne(parameter.text, field);
    core::RestitutionModel& model = *request.restitution_model;
    (parameter.kind == core::RestitutionModelKind::kTc
         ? model.tc
         : (parameter.kind == core::RestitutionModelKind::kThreshold ? model.elastic_below : model.viscoelastic_speed)) =
        value;
  }
  if (app.count("--ring") > 0) request.ring = parseOne(raw.ring, "ring");
}

/// Which events to show. Every scene of a file at once: the summary rows are the point,
/// so none unless asked for.
void readEventPolicy(const RawOptions& raw, CliRequest& request) {
  const std::string text =
      raw.events_given ? raw.events : (request.action == CliRequest::Action::kRunAll ? "none" : "all");
  const auto events = io::parseEventPolicy(text);
  if (!events) {
    const std::string prefix = "first:";
    const std::string n_problem =
        text.rfind(prefix, 0) == 0 ? io::parseCount(std::string_view(text).substr(prefix.size())).problem : "";
    throw makeCliError(CliReason::kInvalidOption, "events",
                       n_problem.rfind("is too large", 0) == 0
                           ? "'" + text + "': N " + n_problem
                           : "'" + text + "' is not all, none or first:N with N a non-negative integer");
  }
  request.options.events = *events;
  if (raw.full_state_every_given) {
    const io::ParsedCount every = io::parseCount(raw.full_state_every);
    if (!every.problem.empty() || every.value == 0) {
      throw makeCliError(CliReason::kInvalidOption, "full-state-every",
                         "'" + raw.full_state_every + "' " +
                             (every.problem.empty() ? std::string("is not a positive integer: K >= 1") : every.problem));
    }
    request.options.events.full_state_every = every.value;
  }
}

/// --temperature-csv FILE: T(t) of one simulated scene.
void readTemperatureCsv(const RawOptions& raw, CliRequest& request) {
  if (!raw.temperature_csv_given) return;
  if (request.action != CliRequest::Action::kRunOne) {
    throw makeCliError(CliReason::kUsage, "temperature-csv",
                       "T(t) is written for one scene: give --name, --bodies or the three lists");
  }
  if (request.options.mode != core::RunMode::kFull) {
    throw makeCliError(CliReason::kInvalidOption, "temperature-csv",
                       "T(t) needs the simulation's impacts: --mode full (the default)");
  }
  request.temperature_csv = raw.temperature_csv;
}

}  // namespace

const char* cliReasonName(CliReason reason) {
  switch (reason) {
    case CliReason::kUsage: return "USAGE";
    case CliReason::kMalformedNumber: return "MALFORMED_NUMBER";
    case CliReason::kWrongCount: return "WRONG_COUNT";
    case CliReason::kMissingInput: return "MISSING_INPUT";
    case CliReason::kInvalidOption: return "INVALID_OPTION";
    case CliReason::kUnknownScenario: return "UNKNOWN_SCENARIO";
    case CliReason::kScenarioFile: return "SCENARIO_FILE";
    case CliReason::kBodiesFile: return "BODIES_FILE";
  }
  return "UNKNOWN";
}

CliError makeCliError(CliReason reason, std::string field, std::string message) {
  return CliError{cliReasonName(reason), static_cast<int>(reason), std::move(field), oneLine(std::move(message))};
}

io::ReportFormat requestedFormat(const std::vector<std::string>& args) {
  std::optional<io::ReportFormat> format;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--format" && i + 1 < args.size()) format = io::parseReportFormat(args[i + 1]);
    if (args[i].rfind("--format=", 0) == 0) format = io::parseReportFormat(args[i].substr(9));
  }
  return format.value_or(io::ReportFormat::kTable);
}

/// The options and their help texts, read into `raw`.
void declareOptions(CLI::App& app, RawOptions& raw) {
  app.add_option("--masses", raw.masses, "m_A,m_B,... [kg], one per body, right to left; inf makes an end body a wall");
  app.add_option("--positions", raw.positions, "x_A,x_B,... [m], strictly decreasing");
  app.add_option("--velocities", raw.velocities, "v_A,v_B,... [m/s]; negative values are fine");
  app.add_option(
      "--bodies", raw.bodies, "CSV file with the header mass,position,velocity, one body per line, right to left; - reads stdin");
  app.add_option(
      "--restitution", raw.restitution, "e in [0,1] for every pair, or e_AB,e_BC,... one per pair (default 1: elastic)");
  app.add_option("--restitution-model", raw.restitution_model,
                 "constant|tc|threshold|viscoelastic: how each impact's e is chosen (default constant: the pair's e; "
                 "docs/physics.md)");
  app.add_option("--tc", raw.tc, "TC model: t_c [s]; an impact is elastic unless both bodies' last impacts are more than t_c ago");
  app.add_option("--elastic-below", raw.elastic_below, "threshold law: v_0 [m/s]; e = 1 for approach speeds below it");
  app.add_option("--viscoelastic-speed", raw.viscoelastic_speed,
                 "viscoelastic law: v* [m/s] in e(v) = 1 - C1 (v/v*)^(1/5) + C2 (v/v*)^(2/5)");
  app.add_option("--ring", raw.ring, "put the bodies on a ring of circumference L [m] (positions in [0, L), no walls)");
  app.add_option(
      "--max-collisions", raw.max_collisions, "stop after N collisions and mark the run truncated (default 10000000)");
  app.add_flag("--simulate-to-cap", raw.simulate_to_cap,
               "simulate up to --max-collisions even when the model predicts more (default: the model answers at "
               "once; two walls: 1000 impacts shown)");
  app.add_option(
      "--events", raw.events, "events to print: all|none|first:N (default all; none when running every scenario)");
  app.add_option("--full-state-every", raw.full_state_every,
                 "K: JSON and CSV events carry every body's state at impact 1 and every K-th impact, the others "
                 "only their pair's (the lean record of long runs; default 1: every event)");
  app.add_option("--format", raw.format, "table|json|csv (default table)");
  // Removed (every run is exact); kept only to refuse it with its reason, hidden from --help.
  app.add_option("--precision", raw.precision)->group("");
  app.add_option("--mode", raw.mode, "full|predict|summary (default full)");
  app.add_option("--scenario", raw.scenario, "scenario file (YAML); without --name runs every scene in it");
  app.add_option("--name", raw.name, "scene of the scenario file (default file: the package's presets)");
  app.add_flag("--list", raw.list, "list the scenes of the scenario file");
  app.add_option("--temperature-csv", raw.temperature_csv,
                 "write the granular temperature T(t) [J] of the run to this CSV file, with the fit of Haff's law");
}

/// Which options the user gave (a default value is not a choice).
void markGiven(const CLI::App& app, RawOptions& raw) {
  raw.masses_given = app.count("--masses") > 0;
  raw.positions_given = app.count("--positions") > 0;
  raw.velocities_given = app.count("--velocities") > 0;
  raw.bodies_given = app.count("--bodies") > 0;
  raw.restitution_given = app.count("--restitution") > 0;
  raw.max_collisions_given = app.count("--max-collisions") > 0;
  raw.events_given = app.count("--events") > 0;
  raw.scenario_given = app.count("--scenario") > 0;
  raw.name_given = app.count("--name") > 0;
  raw.temperature_csv_given = app.count("--temperature-csv") > 0;
  raw.precision_given = app.count("--precision") > 0;
  raw.full_state_every_given = app.count("--full-state-every") > 0;
}

CliRequest parseCommandLine(const std::vector<std::string>& args, const std::string& default_scenario_path) {
  RawOptions raw;
  CLI::App app{
      "collision_lab_cli: point masses on a line (any number, walls allowed), simulated exactly by the model "
      "each scene needs; three elastic bodies beside the correct closed-form predictions and the paper's "
      "printed formulas (SI units).",
      "collision_lab_cli"};
  declareOptions(app, raw);
  app.allow_extras();  // reported below in the user's order, with a hint

  CliRequest request;
  std::vector<std::string> normalized = normalizeArguments(args);
  std::reverse(normalized.begin(), normalized.end());  // CLI11 takes them last first
  try {
    app.parse(normalized);
  } catch (const CLI::CallForHelp&) {
    request.action = CliRequest::Action::kHelp;
    request.help_text = app.help();
    return request;
  } catch (const CLI::ParseError& e) {
    throw makeCliError(CliReason::kUsage, "arguments", std::string(e.what()) + " (see --help)");
  }
  if (!app.remaining().empty()) {
    std::string unexpected;
    for (const std::string& arg : app.remaining()) unexpected += " " + arg;
    throw makeCliError(CliReason::kUsage, "arguments",
                       "unexpected arguments:" + unexpected +
                           " (lists are comma-separated without blanks, e.g. --velocities -1,0,0; see --help)");
  }
  markGiven(app, raw);

  readRunOptions(raw, request);
  readSceneSource(raw, default_scenario_path, request);
  if (raw.restitution_given) request.restitution = parseList(raw.restitution, "restitution");
  readSceneOptions(app, raw, request);
  readEventPolicy(raw, request);
  readTemperatureCsv(raw, request);
  return request;
}

}  // namespace cli
}  // namespace collision_lab
