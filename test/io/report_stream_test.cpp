// The streamed three-body reports (io/report.h, io/scene_report.h) carry the core's event
// values bit for bit: whole CSV and JSON runs of thousands of impacts (several buffer
// chunks) are parsed back, by strtod and by nlohmann::json, and compared with the events
// that the core's run keeps (SceneSimulation::impacts, each with its model block).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "collision_lab/core/scene_run.h"
#include "collision_lab/core/nbody/models.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/report.h"
#include "collision_lab/io/scene_report.h"
#include "event_pipeline.h"
#include "report_text.h"

namespace {

namespace core = collision_lab::core;
namespace io = collision_lab::io;

std::uint64_t bitsOf(double value) {
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

/// A printed value against the core's: the same bits, except that -0 is printed as 0 and
/// (JSON) NaN and infinities as null, read here as NaN.
bool samePrinted(double printed, double core_value) {
  if (core_value == 0) return bitsOf(printed) == bitsOf(0.0);
  if (std::isnan(core_value)) return std::isnan(printed);
  return bitsOf(printed) == bitsOf(core_value);
}

/// The numeric cells of one event row (the columns of report_text::kEventCsvHeader without
/// the counts, names and flags; a per-body cell holds its values separated by ';').
const std::vector<std::size_t> kImpactNumberColumns = {5, 6, 7, 11, 12, 13, 14, 15, 16, 17, 18, 19,
                                                       20, 21, 22, 23, 24, 25, 26, 27, 28};

std::vector<double> csvRowValues(const core::ImpactRecord& impact) {
  const core::ImpactModelValues& m = *impact.model;
  const std::size_t p = impact.pair_index;
  std::vector<double> values = {impact.time, impact.position, 1.0};  // restitution: elastic
  for (const auto* group : {&m.velocities_before, &m.velocities_after, &m.energy_transfer}) {
    values.push_back((*group)[p]);
    values.push_back((*group)[p + 1]);
  }
  values.push_back(0.0);  // energy lost
  for (const auto* group : {&m.positions, &m.velocities_before, &m.velocities_after, &m.energy_transfer,
                            &m.kinetic_energy_after}) {
    values.insert(values.end(), group->begin(), group->end());
  }
  values.push_back(m.total_energy);
  values.push_back(m.total_momentum);
  for (const auto* group : {&m.predicted_velocities_after, &m.predicted_energy_transfer,
                            &m.paper_velocities_after, &m.paper_energy_transfer}) {
    values.insert(values.end(), group->begin(), group->end());
  }
  return values;
}

struct LabRun {
  io::SceneEntry entry;
  core::RunOptions options;
  core::SceneRunResult result;
  const std::vector<core::ImpactRecord>& events() const { return result.simulation.impacts; }
};

LabRun runScene(const core::Scene& scene) {
  LabRun run{{"stream", "", scene, 0}, {}, {}};
  run.options.events = core::EventPolicy::all();
  core::SceneRunOptions options;
  options.lab = run.options;
  run.result = core::runScene(core::planScene(run.entry.scene), options);
  return run;
}

/// The report as the CLI writes it (the scene report, which states the model) or as its
/// three-body layout alone does (report_text.h).
std::string report(const LabRun& run, io::ReportFormat format, bool with_model) {
  std::ostringstream out;
  if (with_model) {
    const auto writer = io::makeSceneReportWriter(format, out);
    writer->begin(run.entry, run.options, run.result.model, run.result.prediction);
    for (const core::ImpactRecord& event : run.events()) writer->impact(event);
    writer->end(run.result);
  } else {
    const auto writer = io::makeRunReportWriter(format, out);
    writer->begin(run.entry, run.options);
    for (const core::ImpactRecord& event : run.events()) writer->event(event);
    writer->end(run.result);
  }
  return out.str();
}

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (std::size_t at; (at = line.find(separator, start)) != std::string::npos; start = at + 1) {
    fields.push_back(line.substr(start, at - start));
  }
  fields.push_back(line.substr(start));
  return fields;
}

/// The numbers of the given columns of a row, per-body cells split at ';', empty cells left out.
std::vector<double> csvNumbers(const std::vector<std::string>& fields, const std::vector<std::size_t>& columns) {
  std::vector<double> values;
  for (std::size_t c : columns) {
    if (fields.at(c).empty()) continue;
    for (const std::string& cell : split(fields[c], ';')) {
      char* end = nullptr;
      values.push_back(std::strtod(cell.c_str(), &end));
      EXPECT_EQ(*end, '\0') << cell;
    }
  }
  return values;
}

void expectCsvCarriesEvents(const std::string& text, const std::vector<core::ImpactRecord>& events) {
  std::istringstream in(text);
  std::string line;
  std::size_t row = 0;
  bool header_seen = false;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) continue;
    if (!header_seen) {
      header_seen = true;
      ASSERT_EQ(line.rfind("kind,index,pair,pair_index,bodies,time_s", 0), 0u) << line;
      continue;
    }
    ASSERT_LT(row, events.size());
    const core::ImpactRecord& lab = events[row++];
    const std::vector<std::string> fields = split(line, ',');
    ASSERT_EQ(fields.size(), 29u) << line;
    ASSERT_EQ(fields[0], "impact");
    ASSERT_EQ(fields[1], std::to_string(lab.index));
    ASSERT_EQ(fields[2], core::pairName(lab.pair_index));
    const std::vector<double> expected = csvRowValues(lab);
    const std::vector<double> printed = csvNumbers(fields, kImpactNumberColumns);
    ASSERT_EQ(printed.size(), expected.size()) << line;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      ASSERT_TRUE(samePrinted(printed[i], expected[i])) << "row " << row << " value " << i << ": " << line;
    }
  }
  EXPECT_EQ(row, events.size());
}

/// Every number token of the first `lines` event lines of a JSON report has the fewest
/// significant digits that read back (brute force over printf's %.{p}g); nlohmann's own
/// Grisu2 dump, which the JSON used before, gives 17 where 16 do in a few of them.
void expectShortestJsonNumbers(const std::string& text, std::size_t lines) {
  std::istringstream in(text);
  std::string line;
  std::size_t checked = 0;
  while (std::getline(in, line) && checked < lines) {
    if (line.rfind("{\"kind\":", 0) != 0) continue;
    ++checked;
    for (std::size_t i = line.find(':'); i < line.size(); ++i) {
      if (line[i] != ':' && line[i] != '[' && line[i] != ',') continue;
      const std::size_t end = line.find_first_not_of("-+.0123456789e", i + 1);
      const std::string token = line.substr(i + 1, end - i - 1);
      if (token.find_first_of(".e") == std::string::npos) continue;  // counts, strings, null
      const double value = std::strtod(token.c_str(), nullptr);
      if (value == 0) continue;
      int fewest = 17;
      for (int p = 1; p < 17; ++p) {
        char shorter[40];
        std::snprintf(shorter, sizeof shorter, "%.*g", p, value);
        if (std::strtod(shorter, nullptr) == value) {
          fewest = p;
          break;
        }
      }
      std::string digits;
      for (char c : token.substr(0, token.find('e'))) {
        if (c >= '0' && c <= '9') digits += c;
      }
      digits.erase(0, digits.find_first_not_of('0'));
      digits.erase(digits.find_last_not_of('0') + 1);
      ASSERT_EQ(static_cast<int>(digits.size()), fewest) << token << " in " << line.substr(0, 40);
    }
  }
  EXPECT_EQ(checked, lines);
}

double jsonDouble(const io::Json& value) {
  return value.is_null() ? std::numeric_limits<double>::quiet_NaN() : value.get<double>();
}

/// The "events" of a JSON report against the document API's objects (eventJson,
/// SceneEventJson): the same keys in the same order, the same strings and
/// counts, every double bit for bit (null for NaN and infinities).
void expectJsonEvents(const std::string& text, const std::vector<io::Json>& expected_events) {
  const io::Json doc = io::Json::parse(text);  // throws on invalid JSON
  const io::Json& printed = doc.at("events");
  ASSERT_EQ(printed.size(), expected_events.size());
  for (std::size_t k = 0; k < expected_events.size(); ++k) {
    const io::Json& expected = expected_events[k];
    const io::Json& event = printed[k];
    ASSERT_EQ(event.size(), expected.size());
    auto e = expected.begin();
    for (auto p = event.begin(); p != event.end(); ++p, ++e) {
      ASSERT_EQ(p.key(), e.key());
      if (e->is_array() && !e->empty() && !(*e)[0].is_string()) {
        ASSERT_EQ(p->size(), e->size()) << p.key();
        for (std::size_t i = 0; i < e->size(); ++i) {
          ASSERT_EQ((*p)[i].is_number_float(), std::isfinite(jsonDouble((*e)[i]))) << p.key();  // else null
          ASSERT_TRUE(samePrinted(jsonDouble((*p)[i]), jsonDouble((*e)[i]))) << "event " << k + 1 << " " << p.key();
        }
      } else if (e->is_number_float() || e->is_null()) {
        ASSERT_TRUE(samePrinted(jsonDouble(*p), jsonDouble(*e))) << "event " << k + 1 << " " << p.key();
      } else {
        ASSERT_EQ(*p, *e) << p.key();
      }
    }
  }
}

void expectJsonCarriesEvents(const std::string& text, const std::vector<core::ImpactRecord>& events) {
  std::vector<io::Json> expected;
  for (const core::ImpactRecord& event : events) expected.push_back(io::eventJson(event));
  expectJsonEvents(text, expected);
}

TEST(ReportStream, CsvAndJsonCarryEveryEventValueBitForBit) {
  // Masses (1e8, 1, 1e8): 22214 impacts (ceil(pi / alpha) - 1 with alpha = atan(sqrt(m_B
  // (m_A + m_B + m_C) / (m_A m_C))) = atan(sqrt(2.00000001e-8)), pi / alpha = 22214.4), about
  // 11 MB of CSV: many blocks of the pipeline, formatted by its workers, written in order.
  const LabRun run = runScene({{1e8, 1, 1e8}, {2, 1, 0}, {-1, 0, 0}});
  ASSERT_EQ(run.events().size(), 22214u);
  for (bool with_model : {false, true}) {
    SCOPED_TRACE(with_model ? "with the model" : "report.h writer");
    const std::string csv = report(run, io::ReportFormat::kCsv, with_model);
    EXPECT_GT(csv.size(), std::size_t{10} << 20);
    expectCsvCarriesEvents(csv, run.events());
    const std::string json = report(run, io::ReportFormat::kJson, with_model);
    expectJsonCarriesEvents(json, run.events());
    expectShortestJsonNumbers(json, 400);
  }
}

TEST(ReportStream, WallsZerosAndUndefinedPaperValues) {
  // A wall at C: the wall's values, exact zeros and the paper's undefined expressions (NaN,
  // infinities) print as the conventions say and read back.
  const LabRun run = runScene({{100, 1, std::numeric_limits<double>::infinity()}, {2, 1, 0}, {-1, -0.0, 0}});
  ASSERT_EQ(run.events().size(), 31u);  // m_A / m_B = 100: 31 collisions (shared/physics.md)
  for (bool with_model : {false, true}) {
    expectCsvCarriesEvents(report(run, io::ReportFormat::kCsv, with_model), run.events());
    expectJsonCarriesEvents(report(run, io::ReportFormat::kJson, with_model), run.events());
  }
}

}  // namespace

namespace {

/// An N-body run's shown events, as the document API prints them, and its CSV and JSON.
struct SceneReports {
  std::vector<io::Json> events;
  std::vector<std::vector<double>> csv_values;  ///< the numeric cells of each row, in order
  std::string csv, json;
};

SceneReports sceneReports(const core::Scene& scene) {
  SceneReports reports;
  core::SceneRunOptions options;
  options.lab.events = core::EventPolicy::all();
  options.keep_events = false;
  std::ostringstream csv, json;
  const io::SceneEntry entry{"stream", "", scene, 0};
  const core::ModelChoice model = core::chooseModel(scene);
  const auto csv_writer = io::makeSceneReportWriter(io::ReportFormat::kCsv, csv);
  const auto json_writer = io::makeSceneReportWriter(io::ReportFormat::kJson, json);
  const core::ScenePlan plan = core::planScene(scene);
  csv_writer->begin(entry, options.lab, model, plan.prediction);
  json_writer->begin(entry, options.lab, model, plan.prediction);
  io::SceneEventJson records(scene);
  core::SceneVisitors visitors;
  visitors.impact = [&](const core::ImpactRecord& r) {
    reports.events.push_back(records.impact(r));
    reports.csv_values.push_back({r.time, r.position, r.velocities_before[0], r.velocities_before[1],
                                  r.velocities_after[0], r.velocities_after[1], r.energy_gained[0],
                                  r.energy_gained[1], r.energy_lost});
    csv_writer->impact(r);
    json_writer->impact(r);
  };
  visitors.collapse = [&](const core::Collapse& c) {
    reports.events.push_back(records.collapse(c));
    reports.csv_values.push_back({c.time, c.position, c.velocity, c.velocity});
    csv_writer->collapse(c);
    json_writer->collapse(c);
  };
  const core::SceneRunResult result = core::runScene(core::planScene(scene), options, visitors);
  csv_writer->end(result);
  json_writer->end(result);
  reports.csv = csv.str();
  reports.json = json.str();
  return reports;
}

TEST(ReportStream, NBodyImpactsAndCollapsesCarryTheEngineValues) {
  // 100 bodies (a seeded gas like the gas_1000 preset) and the collapse of three
  // equal masses at e = 0.05 < r_c (a collapse event among the impacts).
  std::mt19937_64 random(13);
  std::uniform_real_distribution<double> speed(-1, 1), mass(0.5, 2);
  core::Scene gas;
  for (int i = 99; i >= 0; --i) {
    gas.masses.push_back(mass(random));
    gas.positions.push_back(i * 0.1);
    gas.velocities.push_back(speed(random));
  }
  const core::Scene collapse{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}};
  for (const core::Scene& scene : {gas, collapse}) {
    ASSERT_FALSE(core::planScene(scene).error);
    const SceneReports reports = sceneReports(scene);
    ASSERT_GT(reports.events.size(), 2u);
    expectJsonEvents(reports.json, reports.events);
    std::istringstream in(reports.csv);
    std::string line;
    std::size_t row = 0;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#' || line.rfind("kind,", 0) == 0) continue;
      ASSERT_LT(row, reports.csv_values.size());
      const std::vector<double>& expected = reports.csv_values[row++];
      const std::vector<std::string> fields = split(line, ',');
      ASSERT_EQ(fields.size(), 29u) << line;
      // time, position; the pair's velocities before (impacts), after, energies and heat (impacts).
      const std::vector<double> printed =
          csvNumbers(fields, fields[0] == "impact" ? std::vector<std::size_t>{5, 6, 11, 12, 13, 14, 15, 16, 17}
                                                   : std::vector<std::size_t>{5, 6, 13, 14});
      ASSERT_EQ(printed.size(), expected.size()) << line;
      for (std::size_t i = 0; i < expected.size(); ++i) ASSERT_TRUE(samePrinted(printed[i], expected[i])) << line;
    }
    EXPECT_EQ(row, reports.csv_values.size());
  }
}

// ---- A failure on a report thread (src/io/event_pipeline.h) ----

/// Writes each event's time as a line, and throws at time 2500.
void formatOrThrow(io::TextSink& sink, const core::ImpactRecord& lab, bool) {
  if (lab.time == 2500) throw std::runtime_error("injected failure at t = 2500");
  sink.count(static_cast<std::uint64_t>(lab.time));
  sink.put('\n');
}

TEST(EventPipeline, AWorkerFailureIsReportedByFinishAndTheRunGoesOn) {
  std::ostringstream out;
  io::EventPipeline pipeline(out, formatOrThrow);
  core::ImpactRecord lab;
  // 10 blocks of 1024 events: the run's pushes must not wait for ever behind the failed one.
  for (int i = 0; i < 10240; ++i) {
    lab.time = i;
    pipeline.push(lab);
  }
  try {
    pipeline.finish();
    ADD_FAILURE() << "finish() did not report the failure";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "writing the events failed: injected failure at t = 2500");
  }
  // What was written is whole blocks before the failed one (events 2048..3071), in order.
  std::istringstream lines(out.str());
  std::uint64_t expected = 0;
  for (std::uint64_t value = 0; lines >> value; ++expected) EXPECT_EQ(value, expected);
  EXPECT_EQ(expected % 1024, 0u);
  EXPECT_LE(expected, 2048u);
}

// The race behind a rare failure of the test above, made certain: the block after the
// failed one is formatted before the failure (its worker then waits its turn), and must not
// be written later. Block 2 (events 2048..3071) waits at its first event until block 3 is
// formatted, then fails. (Failed before: block 3 came out after blocks 0 and 1, from the
// sink's destructor.) Needs two workers, so two hardware threads.
std::mutex race_mutex;
std::condition_variable race_formatted;
bool block_3_formatted = false;

void formatWithARace(io::TextSink& sink, const core::ImpactRecord& lab, bool) {
  if (lab.time == 2048) {
    std::unique_lock<std::mutex> lock(race_mutex);
    race_formatted.wait_for(lock, std::chrono::seconds(30), [] { return block_3_formatted; });
    throw std::runtime_error("injected failure at t = 2048");
  }
  sink.count(static_cast<std::uint64_t>(lab.time));
  sink.put('\n');
  if (lab.time == 4095) {
    std::lock_guard<std::mutex> lock(race_mutex);
    block_3_formatted = true;
    race_formatted.notify_all();
  }
}

TEST(EventPipeline, ABlockFormattedBeforeAnEarlierOneFailedIsNeverWritten) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one hardware thread: one worker, no race";
  std::ostringstream out;
  {
    io::EventPipeline pipeline(out, formatWithARace);
    core::ImpactRecord lab;
    for (int i = 0; i < 4096; ++i) {
      lab.time = i;
      pipeline.push(lab);
    }
    EXPECT_THROW(pipeline.finish(), std::runtime_error);
  }
  EXPECT_TRUE(block_3_formatted) << "block 3 was not formatted while block 2 waited: the test proves nothing";
  std::istringstream lines(out.str());
  std::uint64_t expected = 0;
  for (std::uint64_t value = 0; lines >> value; ++expected) EXPECT_EQ(value, expected);
  EXPECT_EQ(expected, 2048u);
}

}  // namespace
