// collision_lab_io's scenario loader and number parsing, linked directly (no process).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>
#include <unistd.h>

#include "collision_lab/io/number_text.h"
#include "collision_lab/io/scenario_file.h"

namespace {

using collision_lab::validate;
using collision_lab::io::findScenario;
using collision_lab::io::loadScenarioFile;
using collision_lab::io::NamedScene;
using collision_lab::io::parseCount;
using collision_lab::io::parseNumber;
using collision_lab::io::ScenarioFileError;

constexpr double kInf = std::numeric_limits<double>::infinity();
const std::string kData = COLLISION_LAB_SOURCE_DIR "/test/cli/data/";

/// The ScenarioFileError message of loading `path`, or "" if it loads.
std::string loadError(const std::string& path) {
  try {
    loadScenarioFile(path);
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
  EXPECT_EQ(parseNumber(" 2.5e3 ").value, 2500.0);
  EXPECT_EQ(parseNumber("-.5").value, -0.5);
  EXPECT_EQ(parseNumber("0x1p-3").value, 0.125);
  EXPECT_EQ(parseNumber("inf").value, kInf);
  EXPECT_EQ(parseNumber("Infinity").value, kInf);
  EXPECT_EQ(parseNumber(".inf").value, kInf);
  EXPECT_EQ(parseNumber("-.Inf").value, -kInf);
  EXPECT_TRUE(std::isnan(parseNumber("nan").value));
  EXPECT_TRUE(std::isnan(parseNumber(".NaN").value));
  EXPECT_EQ(parseNumber("0.1").value, 0.1);
  EXPECT_EQ(parseNumber("1e-400").value, 0.0);  // underflow rounds, as C does
}

TEST(NumberText, RejectsWhatIsNotOneNumber) {
  EXPECT_EQ(parseNumber("").problem, "is empty");
  EXPECT_EQ(parseNumber("  ").problem, "is empty");
  EXPECT_EQ(parseNumber("two").problem, "is not a number");
  EXPECT_EQ(parseNumber("1 2").problem, "is not a number");
  EXPECT_EQ(parseNumber("1,5").problem, "is not a number");
  EXPECT_EQ(parseNumber("1e400").problem, "is too large for a double");
  EXPECT_EQ(parseNumber("-1e400").problem, "is too large for a double");
}

TEST(NumberText, CountsAreNonNegativeIntegers) {
  EXPECT_EQ(parseCount("0"), 0u);
  EXPECT_EQ(parseCount("10000000"), 10000000u);
  EXPECT_EQ(parseCount("18446744073709551615"), std::numeric_limits<std::uint64_t>::max());
  for (const char* bad : {"", "-1", "+1", "1e6", "1.0", " 1", "18446744073709551616", "abc"}) {
    EXPECT_FALSE(parseCount(bad).has_value()) << bad;
  }
}

TEST(ScenarioFile, PresetsLoadInFileOrderAndAreValid) {
  const std::vector<NamedScene> scenes = loadScenarioFile(COLLISION_LAB_SOURCE_DIR "/config/scenarios.yaml");
  ASSERT_EQ(scenes.size(), 12u);
  EXPECT_EQ(scenes.front().name, "equal_masses");
  EXPECT_EQ(scenes.back().name, "moving_wall");
  for (const NamedScene& named : scenes) {
    EXPECT_FALSE(validate(named.scene).has_value()) << named.name;
    EXPECT_FALSE(named.description.empty()) << named.name;
  }
  const NamedScene pi = findScenario(scenes, "pi_digits_4");
  EXPECT_EQ(pi.scene.masses, (std::array<double, 3>{1e6, 1, kInf}));
  EXPECT_EQ(pi.scene.velocities, (std::array<double, 3>{-1, 0, 0}));
  EXPECT_EQ(pi.max_collisions, 0u);
}

TEST(ScenarioFile, OptionalCollisionCap) {
  const TemporaryYaml file("capped:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
                           "  max_collisions: 5\n");
  EXPECT_EQ(loadScenarioFile(file.path()).at(0).max_collisions, 5u);
  const TemporaryYaml zero("capped:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
                           "  max_collisions: 0\n");
  EXPECT_NE(loadError(zero.path()).find("'max_collisions' must be a positive integer"), std::string::npos);
}

TEST(ScenarioFile, ErrorsNameTheFileTheEntryAndTheField) {
  EXPECT_EQ(loadError(kData + "wrong_count.yaml"),
            kData + "wrong_count.yaml: entry 'two_masses': 'masses' must be a list of 3 numbers [A, B, C]");
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
  const std::vector<NamedScene> scenes = loadScenarioFile(kData + "invalid_physics.yaml");
  ASSERT_EQ(scenes.size(), 2u);
  EXPECT_FALSE(validate(scenes[0].scene).has_value());
  EXPECT_EQ(validate(scenes[1].scene)->reason, collision_lab::Reason::kPositionsNotOrdered);
}

TEST(ScenarioFile, UnknownNameListsTheKnownOnes) {
  const std::vector<NamedScene> scenes = loadScenarioFile(kData + "invalid_physics.yaml");
  try {
    findScenario(scenes, "nosuch");
    FAIL() << "no error";
  } catch (const ScenarioFileError& e) {
    EXPECT_EQ(std::string(e.what()), "no scenario named 'nosuch' (known: fine, unordered)");
  }
}

}  // namespace
