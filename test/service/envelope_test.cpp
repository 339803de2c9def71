// The envelope every input must be in before the lab plans its scene (service/envelope.h):
// the checks, their order and their words (docs/bad_inputs.md), the same for the lab node
// and the web.
#include "collision_lab/service/envelope.h"

#include <gtest/gtest.h>

#include <string>

namespace collision_lab::service {
namespace {

using Reason = EnvelopeRefusal::Reason;

TEST(Envelope, RunIdsAreSafeFileNames) {
  EXPECT_EQ(runIdProblem("pi_digits_3_20261122T054855Z"), "");
  EXPECT_EQ(runIdProblem("a.b-c_D9"), "");
  EXPECT_EQ(runIdProblem(std::string(200, 'a')), "");
  EXPECT_NE(runIdProblem(""), "");
  EXPECT_NE(runIdProblem("../x"), "");
  EXPECT_NE(runIdProblem(".hidden"), "");
  EXPECT_NE(runIdProblem("a/b"), "");
  EXPECT_NE(runIdProblem("a b"), "");
  EXPECT_NE(runIdProblem(std::string(201, 'a')), "");
}

TEST(Envelope, StudentsAreLettersDigitsUnderscoreAndDash) {
  EXPECT_EQ(studentProblem(""), "");  // anonymous
  EXPECT_EQ(studentProblem("ana"), "");
  EXPECT_EQ(studentProblem("Ana_Lima-2"), "");
  EXPECT_EQ(studentProblem(std::string(kMaxStudentLength, 'x')), "");
  EXPECT_NE(studentProblem(std::string(kMaxStudentLength + 1, 'x')), "");
  EXPECT_NE(studentProblem("ana.b"), "");  // '.' separates the student in a run_id
  EXPECT_NE(studentProblem("a/b"), "");
  EXPECT_NE(studentProblem("a b"), "");
  EXPECT_NE(studentProblem("\xc3\xa9"), "");  // UTF-8 e-acute
}

TEST(Envelope, TheRunIdAnInputAsksFor) {
  EXPECT_EQ(requestedRunId("", ""), "");
  EXPECT_EQ(requestedRunId("", "pi_by_hand"), "pi_by_hand");
  EXPECT_EQ(requestedRunId("ana", "pi_by_hand"), "ana.pi_by_hand");
  EXPECT_EQ(requestedRunId("ana", ""), "ana");
}

TEST(Envelope, AnInputWithinItIsTaken) {
  EXPECT_FALSE(checkEnvelope({"", "", 0, 3}, 3));
  EXPECT_FALSE(checkEnvelope({"ana", "pi", 2, 10'000}, 10'000));
  EXPECT_FALSE(checkEnvelope({"ana", "", 1, 0}, 3));  // the core judges an empty scene
}

TEST(Envelope, EachRefusalNamesItsFieldInTheLabsWords) {
  const auto dot = checkEnvelope({"dot.ted", "", 0, 3}, 10);
  ASSERT_TRUE(dot);
  EXPECT_EQ(dot->reason, Reason::kInvalidStudent);
  EXPECT_EQ(dot->field, "student");
  EXPECT_EQ(dot->message,
            "student 'dot.ted' may contain only letters, digits, '_' and '-' ('.' separates it from the run_id)");

  const auto slash = checkEnvelope({"", "a/b", 0, 3}, 10);
  ASSERT_TRUE(slash);
  EXPECT_EQ(slash->reason, Reason::kInvalidRunId);
  EXPECT_EQ(slash->field, "run_id");
  EXPECT_EQ(slash->message, "run_id 'a/b' may contain only letters, digits, '_', '-' and '.'");

  const auto mode = checkEnvelope({"", "", 3, 3}, 10);
  ASSERT_TRUE(mode);
  EXPECT_EQ(mode->reason, Reason::kInvalidMode);
  EXPECT_EQ(mode->field, "mode");
  EXPECT_EQ(mode->message, "mode 3 is not one of MODE_FULL (0), MODE_PREDICT_ONLY (1), MODE_SUMMARY_ONLY (2)");

  const auto big = checkEnvelope({"", "", 0, 11}, 10);
  ASSERT_TRUE(big);
  EXPECT_EQ(big->reason, Reason::kTooManyBodies);
  EXPECT_EQ(big->field, "masses");
  EXPECT_EQ(big->message,
            "11 bodies are more than this node's ~max_bodies = 10; send a smaller scene, or start the node with "
            "a larger ~max_bodies");
}

TEST(Envelope, TheRunIdServedIsCheckedWithTheStudentsNameBeforeIt) {
  // Each part is safe; together they pass 200 characters.
  const auto long_id = checkEnvelope({std::string(64, 's'), std::string(140, 'r'), 0, 3}, 10);
  ASSERT_TRUE(long_id);
  EXPECT_EQ(long_id->reason, Reason::kInvalidRunId);
  EXPECT_NE(long_id->message.find("(<student>.<run_id>) is longer than 200 characters"), std::string::npos)
      << long_id->message;
}

TEST(Envelope, TheFirstProblemInOrderIsTheOneNamed) {
  // Student, run_id, mode, size: an input wrong in all four is refused for its student.
  const auto all = checkEnvelope({"a b", "x/y", 9, 100}, 10);
  ASSERT_TRUE(all);
  EXPECT_EQ(all->reason, Reason::kInvalidStudent);
  const auto three = checkEnvelope({"ab", "x/y", 9, 100}, 10);
  ASSERT_TRUE(three);
  EXPECT_EQ(three->reason, Reason::kInvalidRunId);
  const auto two = checkEnvelope({"ab", "xy", 9, 100}, 10);
  ASSERT_TRUE(two);
  EXPECT_EQ(two->reason, Reason::kInvalidMode);
}

TEST(Envelope, AnOverlongNameIsNotEchoed) {
  const auto refusal = checkEnvelope({std::string(6000, 'n'), "", 0, 3}, 10);
  ASSERT_TRUE(refusal);
  EXPECT_EQ(refusal->reason, Reason::kInvalidStudent);
  EXPECT_EQ(refusal->message, "student is longer than 64 characters");
}

}  // namespace
}  // namespace collision_lab::service
