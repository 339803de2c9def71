#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Scene validScene() { return Scene{{1, 2, 3}, {3, 1, 0}, {-1, 0, 1}}; }

void expectRejected(const Scene& scene, Reason reason, const std::string& field) {
  const auto error = validate(scene);
  ASSERT_TRUE(error.has_value()) << "expected " << reasonName(reason);
  EXPECT_EQ(error->reason, reason) << error->message;
  EXPECT_EQ(error->field, field) << error->message;
  // The field is reported beside the message, which does not repeat it (issue 8).
  EXPECT_FALSE(error->message.empty());
  EXPECT_NE(error->message.rfind(field.substr(0, field.find('[')), 0), 0u) << error->message;
}

TEST(Validation, AcceptsOrdinaryScenesAndWalls) {
  EXPECT_FALSE(validate(validScene()));
  EXPECT_FALSE(validate(Scene{{100, 1, kInf}, {2, 1, 0}, {-1, 0, 0}}));
  EXPECT_FALSE(validate(Scene{{kInf, 1, 1}, {2, 1, 0}, {0.5, 0, 1}}));  // moving wall
  EXPECT_FALSE(validate(Scene{{kInf, 1, kInf}, {2, 1, 0}, {0, 0.5, 0}}));  // a body between two walls
}

TEST(Validation, EveryReasonCode) {
  Scene s = validScene();
  s.velocities[1] = kNaN;
  expectRejected(s, Reason::kNonFiniteValue, "velocities[1]");
  s = validScene();
  s.positions[2] = -kInf;
  expectRejected(s, Reason::kNonFiniteValue, "positions[2]");
  s = validScene();
  s.masses[0] = kNaN;
  expectRejected(s, Reason::kNonFiniteValue, "masses[0]");
  s = validScene();
  s.masses[2] = 0.0;
  expectRejected(s, Reason::kNonPositiveMass, "masses[2]");
  s = validScene();
  s.masses[1] = -1.0;
  expectRejected(s, Reason::kNonPositiveMass, "masses[1]");
  s = validScene();
  s.masses[0] = -kInf;
  expectRejected(s, Reason::kNonPositiveMass, "masses[0]");
  s = validScene();
  s.masses[1] = kInf;
  expectRejected(s, Reason::kWallNotAtEnd, "masses[1]");
  s = validScene();
  s.positions = {0, 1, 2};
  expectRejected(s, Reason::kPositionsNotOrdered, "positions");
  s = validScene();
  s.positions = {1, 1, 0};
  expectRejected(s, Reason::kPositionsCoincident, "positions");
  s = validScene();
  s.masses = {1e200, 1, 1};
  s.velocities = {-1e200, 0, 1};
  expectRejected(s, Reason::kOverflow, "velocities[0]");
  s = validScene();
  s.positions = {1.7e308, -1.7e308, -1.75e308};
  expectRejected(s, Reason::kOverflow, "positions");
  // Counts beyond 64 bits (mass ratio 1e40).
  s = validScene();
  s.masses = {1e40, 1, 1e40};
  expectRejected(s, Reason::kOverflow, "masses");
  // A first contact at t = 1e600 s.
  s = validScene();
  s.positions = {1e300, 0, -1};
  s.velocities = {-1e-300, 0, -1};
  expectRejected(s, Reason::kOverflow, "positions");
}

TEST(Validation, ExactTripleCollisionOnlyWhenTimesAreExactlyEqual) {
  // t_AB = 1 / 1 and t_BC = 1 / 1: all three meet at x = 0 at t = 1.
  Scene triple{{1, 2, 3}, {1, 0, -1}, {-1, 0, 1}};
  expectRejected(triple, Reason::kTripleCollision, "positions");
  // One ulp apart is a valid (near-triple) scene.
  triple.positions[0] = std::nextafter(1.0, 2.0);
  EXPECT_FALSE(validate(triple));
  // Equal only after rounding: 0.1 + 0.2 and 0.3 are different doubles, so not a triple.
  Scene near{{1, 1, 1}, {0.1 + 0.2, 0.0, -0.3}, {-1, 0, 1}};
  EXPECT_FALSE(validate(near));
}

TEST(Validation, NeverThrowsOnHostileInput) {
  const double values[] = {0.0, -0.0, 1.0, -1.0, kInf, -kInf, kNaN, 1e-320, 1e308, -1e308};
  for (double a : values) {
    for (double b : values) {
      Scene s{{a, 1, b}, {b, 0, a}, {a, b, a}};
      EXPECT_NO_THROW(validate(s));
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
