// Seeded random command lines, good and bad mixed: the CLI must always answer with exit 0
// (a report) or exit 2 (one stderr line, and a JSON error document when JSON was asked
// for), never crash or hang. The collision cap keeps every accepted run short.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_process.h"

namespace {

using collision_lab_test::CliOutput;
using collision_lab_test::linesOf;
using collision_lab_test::runCli;

const std::vector<std::string> kNumbers = {
    "1",    "-1",     "0",     "-0",    "2",      "0.5",   "3",      "1e6",    "1e16",   "1e-9",   "inf",
    "-inf", "nan",    ".inf",  "1e308", "-1e308", "1e-320", "5e-324", "1e400", "0x1p3",  "abc",    "",
    "1e160", "-1e160", "1.5.2", "--",   "+2",     " 1",    "1e",     "0x",     "-.5",    "1e-300"};
const std::vector<std::string> kLists = {"masses", "positions", "velocities"};
const std::vector<std::string> kEvents = {"all", "none", "first:2", "first:", "first:-1", "some"};
const std::vector<std::string> kFormats = {"table", "json", "csv", "xml"};
const std::vector<std::string> kPrecisions = {"double", "long_double", "high", "quad"};
const std::vector<std::string> kJunk = {"--speed", "-x", "7", "--list", "--name", "pi_digits_2", "--", "-"};

class RandomCommandLine {
 public:
  explicit RandomCommandLine(unsigned seed) : engine_(seed) {}

  std::vector<std::string> next() {
    std::vector<std::string> args;
    if (chance(0.4)) {
      addPlausibleScene(args);
    } else {
      for (const std::string& list : kLists) {
        if (chance(0.9)) add(args, "--" + list, numberList());
      }
    }
    if (chance(0.3)) add(args, "--events", pick(kEvents));
    if (chance(0.4)) add(args, "--format", pick(kFormats));
    if (chance(0.3)) add(args, "--precision", pick(kPrecisions));
    if (chance(0.15)) args.push_back(pick(kJunk));
    args.insert(args.end(), {"--max-collisions", "2000"});
    return args;
  }

 private:
  bool chance(double p) { return std::bernoulli_distribution(p)(engine_); }

  const std::string& pick(const std::vector<std::string>& pool) {
    return pool[std::uniform_int_distribution<std::size_t>(0, pool.size() - 1)(engine_)];
  }

  /// Mostly valid scenes, walls included, so that accepted runs are common too.
  void addPlausibleScene(std::vector<std::string>& args) {
    const std::vector<std::string> finite_masses = {"1", "2", "0.5", "3", "100", "1e6"};
    const std::vector<std::string> outer_masses = {"1", "2", "0.5", "3", "100", "1e6", "inf"};
    const std::vector<std::string> positions = {"3,1,0", "2,1,-1", "1,0,-1", "0.3,0.2,0.1", "1e3,0,-1e-3"};
    const std::vector<std::string> speeds = {"-1", "0", "1", "0.5", "-2", "1e-9"};
    add(args, "--masses", pick(outer_masses) + "," + pick(finite_masses) + "," + pick(outer_masses));
    add(args, "--positions", pick(positions));
    add(args, "--velocities", pick(speeds) + "," + pick(speeds) + "," + pick(speeds));
  }

  /// Usually three items, sometimes two or four.
  std::string numberList() {
    const int count = chance(0.85) ? 3 : (chance(0.5) ? 2 : 4);
    std::string text;
    for (int i = 0; i < count; ++i) text += (i ? "," : "") + pick(kNumbers);
    return text;
  }

  /// "--opt value" or "--opt=value", as users write either.
  void add(std::vector<std::string>& args, const std::string& option, const std::string& value) {
    if (chance(0.5)) {
      args.push_back(option + "=" + value);
    } else {
      args.insert(args.end(), {option, value});
    }
  }

  std::mt19937 engine_;
};

bool asksForJson(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--format=json" || (args[i] == "--format" && i + 1 < args.size() && args[i + 1] == "json")) {
      return true;
    }
  }
  return false;
}

std::string joined(const std::vector<std::string>& args) {
  std::string text;
  for (const std::string& arg : args) text += " '" + arg + "'";
  return text;
}

TEST(RandomInput, EveryCommandLineGetsAReportOrOneErrorLine) {
  RandomCommandLine generator(20261122);
  int accepted = 0;
  int rejected = 0;
  for (int run = 0; run < 300; ++run) {
    const std::vector<std::string> args = generator.next();
    SCOPED_TRACE("collision_lab_cli" + joined(args));
    const CliOutput result = runCli(args, COLLISION_LAB_SOURCE_DIR);
    ASSERT_TRUE(result.exit_code == 0 || result.exit_code == 2) << "exit " << result.exit_code << ": " << result.err;
    if (result.exit_code == 0) {
      ++accepted;
      EXPECT_EQ(result.err, "");
      EXPECT_FALSE(result.out.empty());
      if (asksForJson(args)) {
        EXPECT_TRUE(nlohmann::json::accept(result.out)) << result.out.substr(0, 200);
      }
      continue;
    }
    ++rejected;
    const std::vector<std::string> lines = linesOf(result.err);
    ASSERT_EQ(lines.size(), 1u) << result.err;
    EXPECT_EQ(lines[0].rfind("collision_lab_cli: invalid ", 0), 0u) << lines[0];
    if (asksForJson(args)) {
      EXPECT_TRUE(nlohmann::json::parse(result.out).at("error").contains("reason")) << result.out;
    } else {
      EXPECT_EQ(result.out, "");
    }
  }
  RecordProperty("accepted", accepted);
  RecordProperty("rejected", rejected);
  // The mix must exercise both paths, or the test proves little.
  EXPECT_GE(accepted, 20);
  EXPECT_GE(rejected, 100);
}

}  // namespace
