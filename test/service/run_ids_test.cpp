// Which run_id a run is served under (service/run_ids.h), against a ledger the test keeps:
// the run index's rows (served, held) and the bags other labs have taken.
#include "collision_lab/service/run_ids.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace collision_lab::service {
namespace {

struct FakeLedger {
  std::set<std::string> served;  ///< listed by the run index
  std::set<std::string> held;    ///< listed, and not ended or with its bag on disk
  std::set<std::string> bags;    ///< bags another lab has taken

  RunIdClaims::Ledger ledger() {
    RunIdClaims::Ledger l;
    l.served_before = [this](const std::string& id) { return served.count(id) > 0; };
    l.held = [this](const std::string& id) { return held.count(id) > 0; };
    l.take_bag = [this](const std::string& id, std::string&) { return bags.count(id) == 0; };
    return l;
  }
};

TEST(RunIds, NumberedRunsAreRecognised) {
  EXPECT_EQ(numberedRunId("run7"), std::make_pair(std::string("run"), std::uint64_t{7}));
  EXPECT_EQ(numberedRunId("ben.run12"), std::make_pair(std::string("ben.run"), std::uint64_t{12}));
  EXPECT_FALSE(numberedRunId("ben.run"));
  EXPECT_FALSE(numberedRunId("benrun3"));  // "run" must start the id or follow a '.'
  EXPECT_FALSE(numberedRunId("pi_31"));
  EXPECT_FALSE(numberedRunId("run" + std::string(19, '9')));  // over 18 digits
}

TEST(RunIds, FreshIdsCountUpSkippingTakenBags) {
  FakeLedger ledger;
  ledger.bags = {"run_x_2"};
  RunIdClaims claims("run_x_", 100, ledger.ledger());
  std::string error;
  EXPECT_EQ(claims.fresh(error), "run_x_1");
  EXPECT_EQ(claims.fresh(error), "run_x_3");
  EXPECT_EQ(claims.fresh(error), "run_x_4");
}

TEST(RunIds, AnAskedIdIsServedAsItsNextFreeName) {
  FakeLedger ledger;
  ledger.held = {"kept"};      // its bag is on disk
  ledger.served = {"gone", "kept"};  // "gone" ended without a bag: it holds nothing
  ledger.bags = {"kept.2"};    // another lab's bag
  RunIdClaims claims("run_", 100, ledger.ledger());
  std::string error;
  EXPECT_EQ(claims.claimAsked("fresh", error), "fresh");
  EXPECT_EQ(claims.claimAsked("fresh", error), "fresh.2") << "this lab gave it out";
  EXPECT_EQ(claims.claimAsked("gone", error), "gone");
  EXPECT_EQ(claims.claimAsked("kept", error), "kept.3");
}

TEST(RunIds, AStudentsNumberedRunGoesOnToANumberNeverServed) {
  FakeLedger ledger;
  ledger.served = {"ben.run1", "ben.run2"};  // an earlier web node numbered these
  RunIdClaims claims("run_", 100, ledger.ledger());
  std::string error;
  EXPECT_EQ(claims.claimAsked("ben.run1", error), "ben.run3");
  EXPECT_EQ(claims.claimAsked("ben.run4", error), "ben.run4");
  EXPECT_EQ(claims.claimAsked("ben.run4", error), "ben.run5");
}

TEST(RunIds, TheMemoryOfIdsGivenOutIsBounded) {
  RememberedRunIds remembered(3);
  for (const char* id : {"a", "b", "c", "d"}) remembered.add(id);
  EXPECT_FALSE(remembered.contains("a")) << "the oldest is forgotten";
  EXPECT_TRUE(remembered.contains("b"));
  EXPECT_TRUE(remembered.contains("d"));
  remembered.add("b");  // again: still one entry
  remembered.add("e");
  EXPECT_FALSE(remembered.contains("b"));
  EXPECT_TRUE(remembered.contains("c"));
}

}  // namespace
}  // namespace collision_lab::service
