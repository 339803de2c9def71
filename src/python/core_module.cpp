// collision_lab._core: the Python module's C++ part (pybind11). A scene goes in as numbers,
// straight into core::Scene and the run options; the run is the CLI's (io::runReported), and
// its report comes back as Python values: the JSON report's scene, options, units and
// summary as dicts (io::ReportValues, key for key), its events as numpy columns filled from
// the event records. No argument strings and no JSON text on the way. Runs without the GIL;
// a run longer than the plan's short ones goes on a watched thread, which turns Ctrl-C (a
// pending KeyboardInterrupt) into the engine's cancel flag.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <future>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/event_record.h"
#include "collision_lab/io/report.h"
#include "collision_lab/io/scene_report.h"
#include "collision_lab/io/temperature_csv.h"

namespace py = pybind11;

namespace collision_lab {
namespace python {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One scene and how to run it, read from run()'s checked keyword arguments (a dict, so that
/// a Dask task can carry it).
struct Job {
  io::SceneEntry entry;
  io::ReportedRun run;
  std::optional<std::uint64_t> events_memory;  ///< the events' budget [bytes]; default a third of the available
  std::string problem_field, problem;  ///< an option the engine cannot take (run() checks them first)
};

std::vector<double> numbers(const py::handle& values) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!array || array.ndim() != 1) throw py::type_error("expected a 1-D sequence of numbers");
  return std::vector<double>(array.data(), array.data() + array.size());
}

/// run()'s keywords: masses, positions, velocities, restitution (a list: [] elastic),
/// ring (None or L), restitution_model (a name), model_parameter (None or its value),
/// max_collisions, simulate_to_cap, events, full_state_every, mode, name, temperature_csv;
/// optionally events_memory (bytes the events' columns may take).
Job readJob(const py::dict& kwargs) {
  Job job;
  core::Scene& scene = job.entry.scene;
  scene.masses = numbers(kwargs["masses"]);
  scene.positions = numbers(kwargs["positions"]);
  scene.velocities = numbers(kwargs["velocities"]);
  scene.restitution = numbers(kwargs["restitution"]);
  if (!kwargs["ring"].is_none()) scene.ring = kwargs["ring"].cast<double>();
  const std::string model = kwargs["restitution_model"].cast<std::string>();
  core::RestitutionModel& restitution = scene.restitution_model;
  for (auto kind : {core::RestitutionModelKind::kConstant, core::RestitutionModelKind::kTc,
                    core::RestitutionModelKind::kThreshold, core::RestitutionModelKind::kViscoelastic}) {
    if (model == core::restitutionModelName(kind)) restitution.kind = kind;
  }
  if (!kwargs["model_parameter"].is_none()) {
    const double parameter = kwargs["model_parameter"].cast<double>();
    switch (restitution.kind) {
      case core::RestitutionModelKind::kTc: restitution.tc = parameter; break;
      case core::RestitutionModelKind::kThreshold: restitution.elastic_below = parameter; break;
      case core::RestitutionModelKind::kViscoelastic: restitution.viscoelastic_speed = parameter; break;
      case core::RestitutionModelKind::kConstant: break;
    }
  }
  job.entry.name = kwargs["name"].cast<std::string>();
  core::RunOptions& options = job.run.options;
  options.max_collisions = kwargs["max_collisions"].cast<std::uint64_t>();
  job.run.simulate_to_cap = kwargs["simulate_to_cap"].cast<bool>();
  const std::string mode_text = kwargs["mode"].cast<std::string>(), events_text = kwargs["events"].cast<std::string>();
  const auto mode = io::parseRunMode(mode_text);
  const auto events = io::parseEventPolicy(events_text);
  if (!mode) job.problem_field = "mode", job.problem = "'" + mode_text + "' is not 'full', 'predict' or 'summary'";
  if (!events) job.problem_field = "events", job.problem = "'" + events_text + "' is not 'all', 'none' or 'first:N'";
  if (mode) options.mode = *mode;
  if (events) options.events = *events;
  options.events.full_state_every = kwargs["full_state_every"].cast<std::uint64_t>();
  if (!kwargs["temperature_csv"].is_none()) job.run.temperature_csv = kwargs["temperature_csv"].cast<std::string>();
  if (kwargs.contains("events_memory")) job.events_memory = kwargs["events_memory"].cast<std::uint64_t>();
  return job;
}

/// A Json value as Python's: what json.loads gives for its text (a NaN or an infinity is
/// null there, so None here).
py::object toPython(const io::Json& json) {
  switch (json.type()) {
    case io::Json::value_t::boolean: return py::bool_(json.get<bool>());
    case io::Json::value_t::number_integer: return py::int_(json.get<std::int64_t>());
    case io::Json::value_t::number_unsigned: return py::int_(json.get<std::uint64_t>());
    case io::Json::value_t::number_float: {
      const double value = json.get<double>();
      return std::isfinite(value) ? py::object(py::float_(value)) : py::object(py::none());
    }
    case io::Json::value_t::string: return py::str(json.get_ref<const std::string&>());
    case io::Json::value_t::array: {
      py::list list(json.size());
      for (std::size_t i = 0; i < json.size(); ++i) list[i] = toPython(json[i]);
      return std::move(list);
    }
    case io::Json::value_t::object: {
      py::dict dict;
      for (const auto& [key, value] : json.items()) dict[py::str(key)] = toPython(value);
      return std::move(dict);
    }
    default: return py::none();
  }
}

/// The memory [bytes] this process can still take without swapping or being killed: the
/// system's MemAvailable, or less where the container's cgroup (v2) limit leaves less;
/// nothing where neither says.
std::optional<std::uint64_t> availableMemory() {
  std::optional<std::uint64_t> available;
  std::ifstream meminfo("/proc/meminfo");
  std::string key, unit;
  std::uint64_t kib = 0;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") available = kib * 1024;
  }
  std::uint64_t limit = 0, used = 0;
  std::ifstream max("/sys/fs/cgroup/memory.max"), current("/sys/fs/cgroup/memory.current");
  if (max >> limit && current >> used) {  // "max" (no limit) does not read as a number
    const std::uint64_t left = limit > used ? limit - used : 0;
    if (!available || left < *available) available = left;
  }
  return available;
}

/// The events' columns grew past what memory can hold (ReportColumns' budget): the run is
/// stopped and refused, with what to ask for instead.
struct ColumnsTooLarge : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The report as values: the JSON's objects, and its events as columns (one entry per
/// event; the per-body arrays as events x bodies rows, NaN where a record has no full state,
/// kept only for scenes of at most io::kFullStateMaxBodies bodies), or none of them
/// (`keep_events` false: the summary alone). The columns may take at most `budget` bytes
/// (default: a third of the memory available when they first reach 2^16 events, since numpy
/// copies them once): past it, event() throws ColumnsTooLarge, which ends the run.
class ReportColumns : public io::ReportValues {
 public:
  ReportColumns(std::optional<std::uint64_t> budget, bool keep_events) : budget_(budget), keep_events_(keep_events) {}

  void head(const io::Json& scene, const io::Json& options, const io::Json& units) override {
    scene_ = scene;
    options_ = options;
    units_ = units;
    bodies_ = scene.at("masses").size();
  }

  void event(const io::EventRecord& r) override {
    if (!keep_events_) return;
    if ((collapse_.size() & 0xffff) == 0xffff) checkBudget();
    collapse_.push_back(r.collapse);
    pair_.push_back(io::eventPairName(r));
    index_.push_back(static_cast<std::int64_t>(r.index));
    pair_index_.push_back(static_cast<std::int64_t>(r.pair_index));
    first_moved_.push_back(static_cast<std::int64_t>(r.first_moved));
    last_moved_.push_back(static_cast<std::int64_t>(r.last_moved));
    cluster_impact_.push_back(r.cluster_impact);
    // The totals belong to the full state: NaN in a lean record, as the JSON's null.
    for (auto [column, value] : {std::pair{&time_, r.time}, std::pair{&position_, r.position},
                                 std::pair{&restitution_, r.restitution}, std::pair{&energy_lost_, r.energy_lost},
                                 std::pair{&total_energy_, r.full_state ? r.total_energy : kNaN},
                                 std::pair{&total_momentum_, r.full_state ? r.total_momentum : kNaN}}) {
      column->push_back(value);
    }
    pair_before_.insert(pair_before_.end(), r.pair_velocities_before.begin(), r.pair_velocities_before.end());
    pair_after_.insert(pair_after_.end(), r.pair_velocities_after.begin(), r.pair_velocities_after.end());
    pair_energy_.insert(pair_energy_.end(), r.pair_energy_transfer.begin(), r.pair_energy_transfer.end());
    const bool full = r.full_state && r.bodies == bodies_ && bodies_ <= io::kFullStateMaxBodies;
    const double* body_values[] = {r.positions, r.velocities_before, r.velocities_after, r.energy_transfer,
                                   r.kinetic_energy_after};
    for (std::size_t k = 0; k < kBodyArrays; ++k) addRow(body_[k], full ? body_values[k] : nullptr, bodies_);
    any_full_state_ = any_full_state_ || full;
    const std::array<double, 3>* model_values[] = {r.predicted_velocities_after, r.paper_velocities_after,
                                                   r.predicted_energy_transfer, r.paper_energy_transfer};
    for (std::size_t k = 0; k < kModelArrays; ++k) {
      addRow(model_[k], model_values[k] ? model_values[k]->data() : nullptr, 3);
      any_model_[k] = any_model_[k] || model_values[k];
    }
    uncertified_.push_back(r.uncertified);
  }

  void summary(const io::Json& summary) override { summary_ = summary; }

  /// The bytes the columns hold now, their vectors' spare capacity included.
  std::uint64_t bytes() const {
    std::uint64_t total = pair_.capacity() * sizeof(std::string) + uncertified_.capacity() * sizeof(std::uint32_t) +
                          collapse_.capacity() + cluster_impact_.capacity();
    for (const auto* column : {&index_, &pair_index_, &first_moved_, &last_moved_}) {
      total += column->capacity() * sizeof(std::int64_t);
    }
    for (const auto* column : {&time_, &position_, &restitution_, &energy_lost_, &total_energy_, &total_momentum_,
                               &pair_before_, &pair_after_, &pair_energy_}) {
      total += column->capacity() * sizeof(double);
    }
    for (const auto& rows : body_) total += rows.capacity() * sizeof(double);
    for (const auto& rows : model_) total += rows.capacity() * sizeof(double);
    return total;
  }

  py::object summaryToPython() const { return python::toPython(summary_); }

  /// {"report": {scene, options, units, summary}, "events": {column: array}}. Needs the GIL.
  py::dict toPython() const {
    py::dict report;
    report["scene"] = python::toPython(scene_);
    report["options"] = python::toPython(options_);
    report["units"] = python::toPython(units_);
    report["summary"] = python::toPython(summary_);
    const std::size_t n = collapse_.size();
    py::dict events;
    events["collapse"] = column(collapse_);
    py::list pairs(n);
    for (std::size_t i = 0; i < n; ++i) pairs[i] = py::str(pair_[i]);
    events["pair"] = std::move(pairs);
    events["index"] = column(index_);
    events["pair_index"] = column(pair_index_);
    events["time"] = column(time_);
    events["position"] = column(position_);
    events["restitution"] = column(restitution_);
    events["energy_lost"] = column(energy_lost_);
    events["total_energy"] = column(total_energy_);
    events["total_momentum"] = column(total_momentum_);
    events["first_moved"] = column(first_moved_);
    events["last_moved"] = column(last_moved_);
    events["cluster_impact"] = column(cluster_impact_);
    events["pair_velocities_before"] = rows(pair_before_, 2);
    events["pair_velocities_after"] = rows(pair_after_, 2);
    events["pair_energy_transfer"] = rows(pair_energy_, 2);
    const char* body_names[] = {"positions", "velocities_before", "velocities_after", "energy_transfer",
                                "kinetic_energy_after"};
    for (std::size_t k = 0; k < kBodyArrays; ++k) {
      events[body_names[k]] = any_full_state_ || n == 0 ? rows(body_[k], bodies_) : py::object(py::none());
    }
    const char* model_names[] = {"predicted_velocities_after", "paper_velocities_after", "predicted_energy_transfer",
                                 "paper_energy_transfer"};
    for (std::size_t k = 0; k < kModelArrays; ++k) {
      if (any_model_[k]) events[model_names[k]] = rows(model_[k], 3);
    }
    py::list uncertified(n);
    const py::tuple none;
    for (std::size_t i = 0; i < n; ++i) {
      if (uncertified_[i] == 0) {
        uncertified[i] = none;
        continue;
      }
      py::list names;
      for (int k = 0; k < core::kImpactValueCount; ++k) {
        if (uncertified_[i] & (1u << k)) names.append(core::impactValueName(k));
      }
      uncertified[i] = py::tuple(names);
    }
    events["uncertified"] = std::move(uncertified);
    py::dict out;
    out["report"] = std::move(report);
    out["events"] = std::move(events);
    return out;
  }

 private:
  static constexpr std::size_t kBodyArrays = 5, kModelArrays = 4;

  void checkBudget() {
    if (!budget_) {
      const std::optional<std::uint64_t> available = availableMemory();
      budget_ = available ? *available / 3 : std::numeric_limits<std::uint64_t>::max();
    }
    const std::uint64_t held = bytes();
    if (held <= *budget_) return;
    const auto mib = [](std::uint64_t b) { return std::to_string(b / (std::uint64_t{1} << 20)) + " MiB"; };
    throw ColumnsTooLarge("the events of this run outgrew the memory that can hold them: " +
                          std::to_string(collapse_.size()) + " events of " + std::to_string(bodies_) + " bodies took " +
                          mib(held) + " of the " + mib(*budget_) +
                          " the run may use. Ask for fewer: events='first:N' "
                          "or 'none' (the summary and state_at still work), full_state_every=K, or a lower max_collisions");
  }

  /// Appends one row of `width` values, NaN for a null `values`, while the rows are kept.
  void addRow(std::vector<double>& to, const double* values, std::size_t width) const {
    if (bodies_ > io::kFullStateMaxBodies && width == bodies_) return;
    if (values) {
      to.insert(to.end(), values, values + width);
    } else {
      to.insert(to.end(), width, kNaN);
    }
  }

  template <class T>
  static py::array column(const std::vector<T>& values) {
    using Stored = std::conditional_t<std::is_same_v<T, char>, bool, T>;
    py::array_t<Stored> array(static_cast<py::ssize_t>(values.size()));
    std::memcpy(array.mutable_data(), values.data(), values.size() * sizeof(T));
    return std::move(array);
  }

  static py::array rows(const std::vector<double>& values, std::size_t width) {
    py::array_t<double> array({static_cast<py::ssize_t>(width == 0 ? 0 : values.size() / width),
                               static_cast<py::ssize_t>(width)});
    std::memcpy(array.mutable_data(), values.data(), values.size() * sizeof(double));
    return std::move(array);
  }

  std::optional<std::uint64_t> budget_;
  bool keep_events_;
  io::Json scene_, options_, units_, summary_;
  std::size_t bodies_ = 0;
  std::vector<char> collapse_, cluster_impact_;
  std::vector<std::string> pair_;
  std::vector<std::int64_t> index_, pair_index_, first_moved_, last_moved_;
  std::vector<double> time_, position_, restitution_, energy_lost_, total_energy_, total_momentum_;
  std::vector<double> pair_before_, pair_after_, pair_energy_;
  std::array<std::vector<double>, kBodyArrays> body_;
  bool any_full_state_ = false;
  std::array<std::vector<double>, kModelArrays> model_;
  std::array<bool, kModelArrays> any_model_{};
  std::vector<std::uint32_t> uncertified_;
};

/// What one job gave: its report as columns, or the error that refused it (the CLI's
/// reasons and codes; the field as run()'s keyword).
struct Outcome {
  std::optional<ReportColumns> report;
  std::string reason, field, message;
  int code = 0;
  std::string too_large;  ///< ColumnsTooLarge's message: {"memory": it}, Python's MemoryError

  /// `summary_only`: the report's summary alone, {"summary": ...} (a sweep's row).
  py::dict toPython(bool summary_only = false) const {
    if (report && summary_only) {
      py::dict out;
      out["summary"] = report->summaryToPython();
      return out;
    }
    if (report) return report->toPython();
    if (!too_large.empty()) {
      py::dict out;
      out["memory"] = too_large;
      return out;
    }
    py::dict error;
    error["reason"] = reason;
    error["code"] = code;
    error["field"] = field;
    error["message"] = message;
    py::dict out;
    out["error"] = std::move(error);
    return out;
  }
};

constexpr int kInvalidOption = 104;  // the CLI's INVALID_OPTION (docs/cli.md)

/// A job's plan, or the outcome that refuses it. Needs no GIL.
struct PlannedJob {
  std::optional<core::ScenePlan> plan;
  Outcome refused;
};

PlannedJob planJob(const Job& job) {
  PlannedJob planned;
  if (!job.problem_field.empty()) {
    planned.refused = {std::nullopt, "INVALID_OPTION", job.problem_field, job.problem, kInvalidOption};
    return planned;
  }
  core::ScenePlan plan = core::planScene(job.entry.scene);
  if (const auto& error = plan.error) {
    planned.refused = {std::nullopt, core::reasonName(error->reason), error->field, error->message,
                       static_cast<int>(error->reason)};
    return planned;
  }
  planned.plan = std::move(plan);
  return planned;
}

/// Runs a planned job, stopped when `cancel` is set; `summary_only`: its events are not kept.
/// Needs no GIL.
Outcome runPlanned(const Job& job, const core::ScenePlan& plan, const std::atomic<bool>* cancel,
                   bool summary_only = false) {
  Outcome outcome;
  io::ReportedRun run = job.run;
  run.cancel = cancel;
  ReportColumns columns(job.events_memory, !summary_only);
  const auto writer = io::makeSceneReportValues(columns);
  try {
    io::runReported(job.entry, plan, run, *writer);
  } catch (const io::CannotOpenFile& e) {
    outcome = {std::nullopt, "INVALID_OPTION", "temperature_csv", e.what(), kInvalidOption};
    return outcome;
  } catch (const ColumnsTooLarge& e) {
    outcome.too_large = e.what();
    if (run.temperature_csv) outcome.too_large += " (the T(t) file ends where the run stopped, without its fit)";
    return outcome;
  }
  outcome.report.emplace(std::move(columns));
  return outcome;
}

/// planJob, then runPlanned keeping the summary alone (run_many's workers). Needs no GIL.
Outcome runSummary(const Job& job, const std::atomic<bool>* cancel) {
  PlannedJob planned = planJob(job);
  return planned.plan ? runPlanned(job, *planned.plan, cancel, true) : std::move(planned.refused);
}

/// Impacts at most of a run that the calling thread runs itself (at most tens of ms).
constexpr std::uint64_t kShortRunImpacts = std::uint64_t{1} << 14;

/// Does the plan know the run to be short (no T(t) file, at most kShortRunImpacts impacts)?
bool isShort(const Job& job, const core::ScenePlan& plan) {
  if (job.run.temperature_csv) return false;
  core::SceneRunOptions options;
  options.lab = job.run.options;
  options.simulate_to_cap = job.run.simulate_to_cap;
  const std::optional<std::uint64_t> impacts = core::plannedImpacts(plan, options);
  return impacts && *impacts <= kShortRunImpacts;
}

/// Runs `work` on its own thread while the calling thread, without the GIL, checks for
/// Python signals every 50 ms. A signal handler that raises (SIGINT: KeyboardInterrupt)
/// sets `cancel`; once `work` has returned, true says so and that exception is pending (the
/// caller raises it, or another). Exceptions of `work` are rethrown (pybind11 turns them
/// into Python's).
template <class Work>
bool runWatchingSignals(std::atomic<bool>& cancel, Work work) {
  std::exception_ptr failure;
  std::promise<void> done;
  std::future<void> finished = done.get_future();
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        work();
      } catch (...) {
        failure = std::current_exception();
      }
      done.set_value();
    });
    while (finished.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      if (interrupted) continue;
      py::gil_scoped_acquire acquire;
      if (PyErr_CheckSignals() != 0) {  // the handler's exception is now the pending error
        interrupted = true;
        cancel.store(true);
      }
    }
    worker.join();
  }
  if (interrupted) return true;
  if (failure) std::rethrow_exception(failure);
  return false;
}

/// (result, interrupted): one scene's result (Outcome::toPython) and whether Ctrl-C stopped
/// it: then the report is of the run as far as it went (its summary cancelled), and the
/// KeyboardInterrupt is cleared for the caller to raise with it. Any other pending exception
/// is raised as it is.
std::pair<py::dict, bool> run(const py::dict& kwargs) {
  const Job job = readJob(kwargs);
  std::atomic<bool> cancel{false};
  PlannedJob planned;
  {
    py::gil_scoped_release release;
    planned = planJob(job);
  }
  if (!planned.plan) return {planned.refused.toPython(), false};
  Outcome outcome;
  if (isShort(job, *planned.plan)) {
    // On this thread, without a watcher (a thread per call would cost more than the run):
    // Ctrl-C is taken when the run has ended, within milliseconds.
    {
      py::gil_scoped_release release;
      outcome = runPlanned(job, *planned.plan, &cancel);
    }
    return {outcome.toPython(), false};
  }
  std::exception_ptr failure;
  const bool interrupted = runWatchingSignals(cancel, [&] {
    try {
      outcome = runPlanned(job, *planned.plan, &cancel);
    } catch (...) {
      failure = std::current_exception();
    }
  });
  // Only Ctrl-C with a report to show becomes RunInterrupted: another handler's exception
  // (a timeout, sys.exit) and a run that failed keep theirs.
  if (interrupted && (failure || !outcome.report || !PyErr_ExceptionMatches(PyExc_KeyboardInterrupt))) {
    throw py::error_already_set();
  }
  if (failure) std::rethrow_exception(failure);
  if (interrupted) PyErr_Clear();
  return {outcome.toPython(), interrupted};
}

/// Every job on `workers` threads (each takes the next job not yet taken); the results in
/// the jobs' order, each {"summary": ...} or a refusal as run() gives it (a sweep's rows:
/// no events). Ctrl-C cancels every run that has not finished.
py::list runMany(const py::list& jobs_given, unsigned workers) {
  std::vector<Job> jobs;
  for (const py::handle& kwargs : jobs_given) jobs.push_back(readJob(kwargs.cast<py::dict>()));
  std::atomic<bool> cancel{false};
  std::vector<Outcome> outcomes(jobs.size());
  const bool interrupted = runWatchingSignals(cancel, [&] {
    std::atomic<std::size_t> next{0};
    std::vector<std::exception_ptr> failures(std::max(1u, workers));
    const auto drain = [&](std::exception_ptr& failure) {
      try {
        for (std::size_t i = next++; i < jobs.size(); i = next++) outcomes[i] = runSummary(jobs[i], &cancel);
      } catch (...) {
        failure = std::current_exception();
        next = jobs.size();  // the others stop after their current job
      }
    };
    std::vector<std::thread> threads;
    for (std::size_t t = 1; t < failures.size(); ++t) threads.emplace_back(drain, std::ref(failures[t]));
    drain(failures[0]);
    for (std::thread& thread : threads) thread.join();
    for (const std::exception_ptr& failure : failures) {
      if (failure) std::rethrow_exception(failure);
    }
  });
  if (interrupted) throw py::error_already_set();
  py::list results;
  for (const Outcome& outcome : outcomes) results.append(outcome.toPython(true));
  return results;
}

}  // namespace
}  // namespace python
}  // namespace collision_lab

PYBIND11_MODULE(_core, m) {
  m.doc() = "collision_lab's C++ core, run in process: a scene's report as Python values and numpy columns.";
  m.attr("version") = COLLISION_LAB_VERSION;  // package.xml's, as the node's RunParameters
  m.def("run", &collision_lab::python::run, py::arg("kwargs"),
        "(result, interrupted): one scene given as run()'s checked keywords (a dict), run as the CLI runs it. "
        "result: {'report': the JSON report's scene, options, units and summary, 'events': numpy columns}, "
        "{'error': {reason, code, field, message}} or {'memory': why the events were refused}; interrupted: Ctrl-C cancelled it (the report is then of "
        "the run as far as it went). Runs without the GIL.");
  m.def("run_many", &collision_lab::python::runMany, py::arg("jobs"), py::arg("workers"),
        "run() of every job (a list of dicts) on `workers` C++ threads, without the GIL; in order, each "
        "{'summary': the report's summary} or run()'s refusal.");
}
