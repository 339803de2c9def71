// The CLI run as a user runs it, from the source folder, with --format json: the helpers
// that the CLI tests share. Header-only; needs COLLISION_LAB_SOURCE_DIR.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_process.h"

namespace collision_lab_test {

using Json = nlohmann::json;

inline const std::string kPresets = COLLISION_LAB_SOURCE_DIR "/config/scenarios.yaml";

inline CliOutput run(const std::vector<std::string>& args, const std::string& stdin_path = "/dev/null") {
  return runCli(args, COLLISION_LAB_SOURCE_DIR, stdin_path);
}

/// Runs with --format json and expects success and one JSON document on stdout.
inline Json runJson(std::vector<std::string> args, const std::string& stdin_path = "/dev/null") {
  args.insert(args.end(), {"--format", "json"});
  const CliOutput result = run(args, stdin_path);
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.err, "");
  return Json::parse(result.out);
}

/// A preset of config/scenarios.yaml, as JSON, with `extra` options.
inline Json runPreset(const std::string& name, std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"--scenario", kPresets, "--name", name};
  args.insert(args.end(), extra.begin(), extra.end());
  return runJson(args);
}

inline std::vector<double> doubles(const Json& array) { return array.get<std::vector<double>>(); }

}  // namespace collision_lab_test
