// Every row of docs/bad_inputs.md, run through collision_lab_cli: the catalogue is the
// test data, so the table and the CLI cannot drift apart. Each row must exit 2 with
// exactly its documented stderr line and nothing on stdout; with --format json added, the
// stdout document must carry the same reason, code, field and message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_process.h"
#include "collision_lab/core/scene.h"

namespace {

using collision_lab_test::CliOutput;
using collision_lab_test::linesOf;
using collision_lab_test::runCli;

struct CatalogueRow {
  int number = 0;
  std::vector<std::string> args;
  std::string reason;
  int code = 0;
  std::string field;
  std::string stderr_line;
};

/// gtest names a failing row by its arguments instead of dumping its bytes.
void PrintTo(const CatalogueRow& row, std::ostream* out) {
  *out << "row " << row.number << ":";
  for (const std::string& arg : row.args) *out << " " << arg;
}

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(' ');
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(' ') - first + 1);
}

/// "`text`" -> "text"; anything else is returned trimmed.
std::string unquote(const std::string& cell) {
  const std::string text = trim(cell);
  return text.size() >= 2 && text.front() == '`' && text.back() == '`' ? text.substr(1, text.size() - 2) : text;
}

/// Splits the Arguments cell as a shell would for these rows: at blanks, except inside
/// single quotes ('1, 1,1' is one argument).
std::vector<std::string> splitArguments(const std::string& text) {
  std::vector<std::string> args;
  std::string current;
  bool quoted = false, any = false;
  for (char c : text) {
    if (c == '\'') {
      quoted = !quoted;
      any = true;
    } else if (c == ' ' && !quoted) {
      if (any) args.push_back(current);
      current.clear();
      any = false;
    } else {
      current += c;
      any = true;
    }
  }
  if (any) args.push_back(current);
  return args;
}

/// Table rows "| n | what | `args` | REASON | code | `field` | `stderr line` |".
std::vector<CatalogueRow> loadCatalogue() {
  std::ifstream in(COLLISION_LAB_SOURCE_DIR "/docs/bad_inputs.md");
  std::vector<CatalogueRow> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| ", 0) != 0) continue;
    std::vector<std::string> cells;
    std::size_t start = 1;
    for (std::size_t bar; (bar = line.find(" |", start)) != std::string::npos; start = bar + 2) {
      cells.push_back(line.substr(start, bar - start));
    }
    const std::string number = cells.empty() ? "" : trim(cells[0]);
    if (cells.size() != 7 || number.empty() || !std::isdigit(static_cast<unsigned char>(number[0]))) continue;
    CatalogueRow row;
    row.number = std::stoi(number);
    row.args = splitArguments(unquote(cells[2]));
    row.reason = trim(cells[3]);
    row.code = std::stoi(trim(cells[4]));
    row.field = unquote(cells[5]);
    row.stderr_line = unquote(cells[6]);
    rows.push_back(row);
  }
  return rows;
}

class BadInput : public ::testing::TestWithParam<CatalogueRow> {};

TEST_P(BadInput, ExitsTwoWithOneLineNamingFieldAndReason) {
  const CatalogueRow& row = GetParam();
  const CliOutput plain = runCli(row.args, COLLISION_LAB_SOURCE_DIR);
  EXPECT_EQ(plain.exit_code, 2);
  EXPECT_EQ(plain.out, "");
  EXPECT_EQ(linesOf(plain.err), std::vector<std::string>{row.stderr_line});
  const std::string prefix = "collision_lab_cli: invalid " + row.field + " (" + row.reason + "): ";
  ASSERT_EQ(row.stderr_line.rfind(prefix, 0), 0u) << "the documented line must name the field and the reason";
  const std::string message = row.stderr_line.substr(prefix.size());

  if (std::find(row.args.begin(), row.args.end(), "--format") != row.args.end()) return;
  std::vector<std::string> json_args = row.args;
  json_args.insert(json_args.end(), {"--format", "json"});
  const CliOutput json = runCli(json_args, COLLISION_LAB_SOURCE_DIR);
  EXPECT_EQ(json.exit_code, 2);
  EXPECT_EQ(linesOf(json.err), std::vector<std::string>{row.stderr_line});
  const nlohmann::json error = nlohmann::json::parse(json.out).at("error");
  EXPECT_EQ(error.at("reason"), row.reason);
  EXPECT_EQ(error.at("code"), row.code);
  EXPECT_EQ(error.at("field"), row.field);
  EXPECT_EQ(error.at("message"), message);
}

INSTANTIATE_TEST_SUITE_P(Catalogue, BadInput, ::testing::ValuesIn(loadCatalogue()),
                         [](const ::testing::TestParamInfo<CatalogueRow>& info) {
                           return "row_" + std::to_string(info.param.number);
                         });

TEST(BadInputCatalogue, HasTwentyRowsAndEveryReasonCode) {
  const std::vector<CatalogueRow> rows = loadCatalogue();
  EXPECT_GE(rows.size(), 20u);
  std::set<std::string> reasons;
  for (const CatalogueRow& row : rows) reasons.insert(row.reason);
  // Every core validation reason (nbody/scene.h, codes 1-13: the CLI takes scenes of any
  // size, issue 10) ...
  namespace core = collision_lab::core;
  for (int code = 1; code <= static_cast<int>(core::Reason::kWallNotAtEnd); ++code) {
    if (code == static_cast<int>(core::Reason::kInfiniteMiddleMass)) continue;  // no longer given (issue 20)
    const std::string name = core::reasonName(static_cast<core::Reason>(code));
    EXPECT_EQ(reasons.count(name), 1u) << "no catalogue row for " << name;
  }
  // ... and every reason of the CLI itself (src/cli/command_line.h).
  for (const char* name : {"USAGE", "MALFORMED_NUMBER", "WRONG_COUNT", "MISSING_INPUT", "INVALID_OPTION",
                           "UNKNOWN_SCENARIO", "SCENARIO_FILE", "BODIES_FILE"}) {
    EXPECT_EQ(reasons.count(name), 1u) << "no catalogue row for " << name;
  }
}

}  // namespace
