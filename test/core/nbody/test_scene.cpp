// N-body scene: names and validation (every reason code, exact first-contact ties).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Scene cradle() { return Scene{{1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}, {}}; }

void expectRejected(const Scene& scene, Reason reason, const std::string& field) {
  const auto error = validate(scene);
  ASSERT_TRUE(error.has_value()) << "expected " << reasonName(reason);
  EXPECT_EQ(error->reason, reason) << error->message;
  EXPECT_EQ(error->field, field) << error->message;
  // Front ends show the field beside the message, which therefore does not repeat it.
  EXPECT_NE(error->message.rfind(field.substr(0, field.find('[')), 0), 0u) << error->message;
  EXPECT_FALSE(error->message.empty());
}

TEST(NBodyNames, LettersThenIndices) {
  EXPECT_EQ(bodyName(0), "A");
  EXPECT_EQ(bodyName(25), "Z");
  EXPECT_EQ(bodyName(26), "#26");
  EXPECT_EQ(pairName(0), "AB");
  EXPECT_EQ(pairName(24), "YZ");
  EXPECT_EQ(pairName(25), "Z-#26");
  EXPECT_EQ(pairName(26), "#26-#27");
}

TEST(NBodyValidation, AcceptsAnyNWallsAndRestitution) {
  EXPECT_FALSE(validate(Scene{{1}, {0}, {3}, {}}));  // N = 1
  EXPECT_FALSE(validate(Scene{{kInf}, {0}, {0}, {}}));  // a lone wall
  EXPECT_FALSE(validate(Scene{{1, 2}, {1, 0}, {-1, 1}, {0.8}}));  // two carts
  EXPECT_FALSE(validate(cradle()));
  EXPECT_FALSE(validate(Scene{{kInf, 1, kInf}, {2, 1, 0}, {0, 1, 0}, {}}));  // a ball between two walls
  EXPECT_FALSE(validate(Scene{{kInf, 1, 2, 3, kInf}, {4, 3, 2, 1, 0}, {0, 1, 0, -1, 0}, {0.0, 0.3, 1.0, 0.5}}));
  Scene n3 = cradle();
  n3.restitution = {0.5};
  EXPECT_FALSE(validate(n3));
}

TEST(NBodyValidation, ShapeReasons) {
  Scene s = cradle();
  s.positions.pop_back();
  expectRejected(s, Reason::kUnequalLengths, "masses");
  const std::string message = validate(s)->message;
  EXPECT_NE(message.find("masses 5"), std::string::npos) << message;
  EXPECT_NE(message.find("positions 4"), std::string::npos) << message;
  EXPECT_NE(message.find("velocities 5"), std::string::npos) << message;
  expectRejected(Scene{}, Reason::kEmptyScene, "masses");
  s = cradle();
  s.restitution = {1, 1};
  expectRejected(s, Reason::kRestitutionCount, "restitution");
  s.restitution = {1, 1, 1, 1, 1};
  expectRejected(s, Reason::kRestitutionCount, "restitution");
  s.restitution = {1, 1, 1.5, 1};
  expectRejected(s, Reason::kRestitutionOutOfRange, "restitution[2]");
  s.restitution = {-0.1};
  expectRejected(s, Reason::kRestitutionOutOfRange, "restitution[0]");
  s.restitution = {1, kNaN, 1, 1};
  expectRejected(s, Reason::kRestitutionOutOfRange, "restitution[1]");
}

TEST(NBodyValidation, ValueReasons) {
  Scene s = cradle();
  s.masses[3] = kNaN;
  expectRejected(s, Reason::kNonFiniteValue, "masses[3]");
  s = cradle();
  s.masses[1] = 0.0;
  expectRejected(s, Reason::kNonPositiveMass, "masses[1]");
  s.masses[1] = -kInf;
  expectRejected(s, Reason::kNonPositiveMass, "masses[1]");
  s = cradle();
  s.masses[2] = kInf;
  expectRejected(s, Reason::kWallNotAtEnd, "masses[2]");
  expectRejected(Scene{{kInf, kInf}, {1, 0}, {0, 0}, {}}, Reason::kTwoWalls, "masses");
  s = cradle();
  s.positions[4] = -kInf;
  expectRejected(s, Reason::kNonFiniteValue, "positions[4]");
  s = cradle();
  s.velocities[2] = kNaN;
  expectRejected(s, Reason::kNonFiniteValue, "velocities[2]");
  s = cradle();
  s.positions[2] = 3;
  expectRejected(s, Reason::kPositionsCoincident, "positions");
  s = cradle();
  s.positions = {4, 3, 1, 2, 0};
  expectRejected(s, Reason::kPositionsNotOrdered, "positions");
  s = cradle();
  s.velocities[0] = 1e300;
  s.masses[0] = 1e10;
  expectRejected(s, Reason::kOverflow, "velocities[0]");
  s = cradle();
  s.masses = {1e-60, 1, 1, 1, 1e60};
  expectRejected(s, Reason::kOverflow, "masses");
  // A first contact beyond the range of a double in time.
  expectRejected(Scene{{1, 1}, {1e300, -1e300}, {-1e-300, 0}, {}}, Reason::kOverflow, "positions");
  // A first contact at t = 1e157 s, well inside the range, that finds A at 1e307 m + 1.7e308 m:
  // the one approaching pair is timed in double, the position then checked exactly.
  const Scene far{{1e-100, 1, 1}, {1.7e308, 1e157, 0}, {1e150, -1, 0}, {}};
  expectRejected(far, Reason::kOverflow, "positions");
  EXPECT_NE(validate(far)->message.find("would find A at 1.8e+308 m"), std::string::npos) << validate(far)->message;
  // Another pair neither approaching nor tied (failed before: boost's "Divide by zero").
  expectRejected(Scene{{1, 1, 1, 1}, {3, 2, 1, 0}, {-1e-310, 0, 0, 0}, {}}, Reason::kOverflow, "positions");
}

TEST(NBodyValidation, FirstContactMultipleCollisionIsExact) {
  // A and C reach B at t = 1 s exactly: two contacts sharing B.
  Scene s{{1, 1, 1, 1}, {2, 1, 0, -5}, {-1, 0, 1, -1}, {}};
  expectRejected(s, Reason::kTripleCollision, "positions");
  EXPECT_NE(validate(s)->message.find("A, B and C"), std::string::npos) << validate(s)->message;
  // One ulp either way separates them: valid.
  s.positions[0] = std::nextafter(2.0, 3.0);
  EXPECT_FALSE(validate(s));
  s.positions[0] = std::nextafter(2.0, 1.0);
  EXPECT_FALSE(validate(s));
  // Disjoint pairs at the same first instant are fine: AB and CD both at t = 1 s.
  EXPECT_FALSE(validate(Scene{{1, 1, 1, 1}, {3, 2, 1, 0}, {-1, 0, 0, 1}, {}}));
  // A tie that is not the first contact is no rejection: A, B and C meet at 2 s, but DE
  // hits at 0.5 s first (the run then ends at the multiple collision; see the engine tests).
  EXPECT_FALSE(validate(Scene{{1, 1, 1, 1, 1}, {20, 10, 0, -10, -10.5}, {-5, 0, 5, -1, 0}, {}}));
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
