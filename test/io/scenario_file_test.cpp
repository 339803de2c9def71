// collision_lab_io's scenario loader and number parsing, linked directly (no process).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>
#include <unistd.h>

#include "collision_lab/io/number_text.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/scenario_file.h"

namespace {

using collision_lab::core::validate;
using collision_lab::io::findScene;
using collision_lab::io::loadScenes;
using collision_lab::io::SceneEntry;
using collision_lab::io::parseCount;
using collision_lab::io::parseNumber;
using collision_lab::io::ScenarioFileError;

constexpr double kInf = std::numeric_limits<double>::infinity();
const std::string kData = COLLISION_LAB_SOURCE_DIR "/test/cli/data/";

/// The ScenarioFileError message of loading `path`, or "" if it loads.
std::string loadError(const std::string& path) {
  try {
    loadScenes(path);
  } catch (const ScenarioFileError& e) {
    return e.what();
  }
  return "";
}

/// Writes `content` to a fresh file in a unique temporary folder; removes it afterwards.
class TemporaryYaml {
 public:
  explicit TemporaryYaml(const std::string& content) {
    char dir_template[] = "/tmp/collision_lab_io_test_XXXXXX";
    dir_ = mkdtemp(dir_template);
    path_ = dir_ + "/scenarios.yaml";
    std::ofstream(path_) << content;
  }
  ~TemporaryYaml() {
    unlink(path_.c_str());
    rmdir(dir_.c_str());
  }
  const std::string& path() const { return path_; }

 private:
  std::string dir_;
  std::string path_;
};

TEST(NumberText, ReadsNumbersPeopleType) {
  EXPECT_EQ(parseNumber("-1").value, -1.0);
  EXPECT_EQ(parseNumber("2.5e3").value, 2500.0);
  EXPECT_EQ(parseNumber("-.5").value, -0.5);
  EXPECT_EQ(parseNumber("0x1p-3").value, 0.125);
  EXPECT_EQ(parseNumber("inf").value, kInf);
  EXPECT_EQ(parseNumber("Infinity").value, kInf);
  EXPECT_EQ(parseNumber(".inf").value, kInf);
  EXPECT_EQ(parseNumber("-.Inf").value, -kInf);
  EXPECT_TRUE(std::isnan(parseNumber("nan").value));
  EXPECT_TRUE(std::isnan(parseNumber(".NaN").value));
  EXPECT_EQ(parseNumber("0.1").value, 0.1);
  // Subnormal numbers are read as the nearest double (issue 14 uses 5e-324).
  EXPECT_EQ(parseNumber("5e-324").value, std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(parseNumber("-1e-320").value, -1e-320);
  EXPECT_TRUE(parseNumber("-1e-320").problem.empty());
  EXPECT_EQ(parseNumber("0e-400").value, 0.0);  // zero written with an exponent is zero
  EXPECT_TRUE(parseNumber("0e-400").problem.empty());
}

TEST(NumberText, RejectsWhatIsNotOneNumber) {
  EXPECT_EQ(parseNumber("").problem, "is empty");
  // One rule for blanks: none (issue 14 found "1, 1,1" accepted while the CLI said otherwise).
  for (const char* blank : {"  ", " 2.5e3 ", " 1", "1 ", "\t1"}) {
    EXPECT_EQ(parseNumber(blank).problem, "contains a blank; numbers are written without blanks") << blank;
  }
  EXPECT_EQ(parseNumber("two").problem, "is not a number");
  EXPECT_EQ(parseNumber("1 2").problem, "contains a blank; numbers are written without blanks");
  EXPECT_EQ(parseNumber("1,5").problem, "is not a number");
  EXPECT_EQ(parseNumber("1e400").problem, "is too large for a double");
  EXPECT_EQ(parseNumber("-1e400").problem, "is too large for a double");
  // Underflow to zero is an error like overflow, never a silent 0 (issue 14).
  const std::string too_small = "is too small for a double (it would be read as 0; the smallest is 4.9e-324); write 0 for zero";
  for (const char* tiny : {"1e-400", "-1e-400", "2e-324", "0x1p-1080"}) EXPECT_EQ(parseNumber(tiny).problem, too_small) << tiny;
}

TEST(NumberText, CountsAreNonNegativeIntegers) {
  EXPECT_EQ(parseCount("0").value, 0u);
  EXPECT_EQ(parseCount("10000000").value, 10000000u);
  EXPECT_EQ(parseCount("18446744073709551615").value, std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(parseCount("000000000000000000000042").value, 42u);
  for (const char* good : {"0", "18446744073709551615", "000000000000000000000042"}) {
    EXPECT_EQ(parseCount(good).problem, "") << good;
  }
  for (const char* bad : {"", "-1", "+1", "1e6", "1.0", " 1", "abc"}) {
    EXPECT_EQ(parseCount(bad).problem, "is not a non-negative integer") << bad;
  }
  // Too large says so (issue 14: it was "not a non-negative integer").
  for (const char* huge : {"18446744073709551616", "99999999999999999999", "123456789012345678901234567890"}) {
    EXPECT_EQ(parseCount(huge).problem, "is too large: the largest is 2^64 - 1 = 18446744073709551615") << huge;
  }
}

TEST(ScenarioFile, PresetsLoadInFileOrderAndAreValid) {
  const std::vector<SceneEntry> scenes = loadScenes(COLLISION_LAB_SOURCE_DIR "/config/scenarios.yaml");
  ASSERT_EQ(scenes.size(), 24u);
  EXPECT_EQ(scenes.front().name, "equal_masses");
  EXPECT_EQ(scenes[11].name, "moving_wall");
  EXPECT_EQ(scenes.back().name, "cluster_collapse_5");
  for (const SceneEntry& entry : scenes) {
    EXPECT_FALSE(validate(entry.scene).has_value()) << entry.name;
    EXPECT_FALSE(entry.description.empty()) << entry.name;
  }
  const SceneEntry pi = findScene(scenes, "pi_digits_4");
  EXPECT_EQ(pi.scene.masses, (std::vector<double>{1e6, 1, kInf}));
  EXPECT_EQ(pi.scene.velocities, (std::vector<double>{-1, 0, 0}));
  EXPECT_EQ(pi.max_collisions, 0u);
}

TEST(ScenarioFile, PresetsOfAnySizeLoadAndAreValid) {
  const std::vector<SceneEntry> scenes = loadScenes(COLLISION_LAB_SOURCE_DIR "/config/scenarios.yaml");
  ASSERT_EQ(scenes.size(), 24u);
  for (const SceneEntry& entry : scenes) {
    EXPECT_FALSE(collision_lab::core::planScene(entry.scene).error.has_value()) << entry.name;
    EXPECT_FALSE(entry.description.empty()) << entry.name;
  }
  const SceneEntry gas = findScene(scenes, "gas_1000");  // from config/gas_1000.csv
  ASSERT_EQ(gas.scene.size(), 1000u);
  EXPECT_EQ(gas.scene.positions.front(), 999.0);
  EXPECT_EQ(gas.scene.positions.back(), 0.0);
  for (std::size_t i = 0; i < gas.scene.size(); ++i) {
    EXPECT_TRUE(gas.scene.masses[i] >= 1.0 && gas.scene.masses[i] <= 2.0) << i;
    EXPECT_TRUE(gas.scene.velocities[i] >= -1.0 && gas.scene.velocities[i] <= 1.0) << i;
  }
  EXPECT_EQ(findScene(scenes, "two_carts_inelastic").scene.restitution, std::vector<double>{0.8});
}

TEST(ScenarioFile, RestitutionAndBodiesKeys) {
  const TemporaryYaml list("a:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
                           "  restitution: [0.5, 1]\n");
  EXPECT_EQ(loadScenes(list.path()).at(0).scene.restitution, (std::vector<double>{0.5, 1}));
  const TemporaryYaml both("a:\n  bodies: x.csv\n  masses: [1]\n");
  EXPECT_NE(loadError(both.path()).find("give either 'bodies' or 'masses', not both"), std::string::npos);
  const TemporaryYaml absent("a:\n  bodies: no_such_file.csv\n");
  EXPECT_NE(loadError(absent.path()).find("cannot open"), std::string::npos);
}

TEST(ScenarioFile, OptionalCollisionCap) {
  const TemporaryYaml file("capped:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
                           "  max_collisions: 5\n");
  EXPECT_EQ(loadScenes(file.path()).at(0).max_collisions, 5u);
  const TemporaryYaml zero("capped:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
                           "  max_collisions: 0\n");
  EXPECT_NE(loadError(zero.path()).find("'max_collisions' must be a positive integer"), std::string::npos);
  const TemporaryYaml huge("capped:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
                           "  max_collisions: 99999999999999999999\n");
  EXPECT_EQ(loadError(huge.path()), huge.path() + ": entry 'capped': 'max_collisions' 99999999999999999999 is too "
                                                  "large: the largest is 2^64 - 1 = 18446744073709551615");
}

TEST(ScenarioFile, ErrorsNameTheFileTheEntryAndTheField) {
  // Lists of any length load; different lengths are the physics' to reject (UNEQUAL_LENGTHS).
  const std::vector<SceneEntry> two_masses = loadScenes(kData + "wrong_count.yaml");
  ASSERT_EQ(two_masses.size(), 1u);
  EXPECT_EQ(collision_lab::core::planScene(two_masses[0].scene).error->reason,
            collision_lab::core::Reason::kUnequalLengths);
  const TemporaryYaml empty_list("a:\n  masses: []\n  positions: []\n  velocities: []\n");
  EXPECT_EQ(loadError(empty_list.path()),
            empty_list.path() + ": entry 'a': 'masses' must be a list of numbers, one per body, right to left");
  EXPECT_EQ(loadError(kData + "bad_number.yaml"),
            kData + "bad_number.yaml: entry 'heavy': masses[1] 'heavy' is not a number");
  EXPECT_NE(loadError(kData + "unknown_key.yaml").find("entry 'typo': unknown key 'velocity'"), std::string::npos);
  EXPECT_EQ(loadError(kData + "duplicate_name.yaml"), kData + "duplicate_name.yaml: scenario 'twice' appears twice");
  EXPECT_NE(loadError(kData + "bad_syntax.yaml").find("YAML syntax error at line"), std::string::npos);
  EXPECT_NE(loadError(kData + "not_a_map.yaml").find("expected a map of named scenarios"), std::string::npos);
  EXPECT_EQ(loadError(kData + "absent.yaml"), kData + "absent.yaml: cannot open the scenario file");
  EXPECT_EQ(loadError(kData), kData + ": is a folder, not a scenario file");
  const TemporaryYaml empty("");
  EXPECT_NE(loadError(empty.path()).find("expected a map"), std::string::npos);
  const TemporaryYaml missing("a:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n");
  EXPECT_EQ(loadError(missing.path()), missing.path() + ": entry 'a': 'velocities' is missing");
  const TemporaryYaml nested("a:\n  masses: [1, [1], 1]\n  positions: [2, 1, 0]\n  velocities: [0, 0, 0]\n");
  EXPECT_EQ(loadError(nested.path()), nested.path() + ": entry 'a': masses[1] is not a number");
}

TEST(ScenarioFile, PhysicsIsLeftToValidate) {
  const std::vector<SceneEntry> scenes = loadScenes(kData + "invalid_physics.yaml");
  ASSERT_EQ(scenes.size(), 2u);
  EXPECT_FALSE(validate(scenes[0].scene).has_value());
  EXPECT_EQ(validate(scenes[1].scene)->reason, collision_lab::core::Reason::kPositionsNotOrdered);
}

// Issue 21: the restitution model with its parameter, and the ring (failed before: unknown keys).
TEST(ScenarioFile, RestitutionModelAndRingKeys) {
  using collision_lab::core::RestitutionModelKind;
  const TemporaryYaml file(
      "tc_gas: {masses: [1, 1, 1], positions: [2, 1, 0], velocities: [-1, 0, 0], restitution: 0.5,\n"
      "         restitution_model: tc, tc: 1.0e-3}\n"
      "slow_elastic: {masses: [1, 1], positions: [1, 0], velocities: [-1, 1], restitution: 0.5,\n"
      "               restitution_model: threshold, elastic_below: 0.01}\n"
      "soft: {masses: [1, 1], positions: [1, 0], velocities: [-1, 1], restitution_model: viscoelastic,\n"
      "       viscoelastic_speed: 2}\n"
      "ring: {masses: [1, 3], positions: [9, 1], velocities: [1, -1], ring: 10}\n");
  const std::vector<SceneEntry> scenes = loadScenes(file.path());
  ASSERT_EQ(scenes.size(), 4u);
  const auto tc = findScene(scenes, "tc_gas").scene.restitution_model;
  EXPECT_EQ(tc.kind, RestitutionModelKind::kTc);
  EXPECT_EQ(tc.tc, 1.0e-3);
  const auto threshold = findScene(scenes, "slow_elastic").scene.restitution_model;
  EXPECT_EQ(threshold.kind, RestitutionModelKind::kThreshold);
  EXPECT_EQ(threshold.elastic_below, 0.01);
  const auto soft = findScene(scenes, "soft").scene.restitution_model;
  EXPECT_EQ(soft.kind, RestitutionModelKind::kViscoelastic);
  EXPECT_EQ(soft.viscoelastic_speed, 2.0);
  EXPECT_EQ(findScene(scenes, "ring").scene.ring, 10.0);
  for (const SceneEntry& entry : scenes) EXPECT_FALSE(collision_lab::core::validate(entry.scene).has_value()) << entry.name;
  // A parameter without its model is an error that names it.
  const TemporaryYaml orphan("x: {masses: [1, 1], positions: [1, 0], velocities: [-1, 1], tc: 1}\n");
  EXPECT_NE(loadError(orphan.path()).find("'tc' belongs to restitution_model: tc"), std::string::npos)
      << loadError(orphan.path());
}

TEST(ScenarioFile, UnknownNameListsTheKnownOnes) {
  const std::vector<SceneEntry> scenes = loadScenes(kData + "invalid_physics.yaml");
  try {
    findScene(scenes, "nosuch");
    FAIL() << "no error";
  } catch (const ScenarioFileError& e) {
    EXPECT_EQ(std::string(e.what()), "no scenario named 'nosuch' (known: fine, unordered)");
  }
}

}  // namespace
