// An address's bounded share of the lab (service/address_share.h): places taken by sends
// and runs, given back when a send is refused or a run ends, or after a missed end.
#include <chrono>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "collision_lab/service/address_share.h"

namespace {

using collision_lab::service::AddressShare;
using namespace std::chrono_literals;

TEST(AddressShare, ManyNamesOneAddressHoldAtMostItsShareUntilRunsEnd) {
  AddressShare share(3, 1h);
  std::set<std::string> ended;
  const auto finished = [&](const std::string& run_id) { return ended.count(run_id) > 0; };
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(share.reserve("10.0.0.1", finished));
    share.answered("10.0.0.1", "name" + std::to_string(k) + ".run1");
  }
  EXPECT_FALSE(share.reserve("10.0.0.1", finished));
  EXPECT_TRUE(share.reserve("10.0.0.2", finished));  // another address has its own share
  ended.insert("name1.run1");
  EXPECT_TRUE(share.reserve("10.0.0.1", finished));  // the ended run's place
  EXPECT_FALSE(share.reserve("10.0.0.1", finished));  // the send awaiting its answer holds one
  share.answered("10.0.0.1", std::nullopt);          // refused: given back
  EXPECT_EQ(share.taken("10.0.0.1"), 2u);
  EXPECT_TRUE(share.reserve("10.0.0.1", finished));
}

TEST(AddressShare, AMissedEndIsForgottenAfterItsTime) {
  AddressShare share(1, 10min);
  const auto never = [](const std::string&) { return false; };
  const auto start = AddressShare::Clock::now();
  ASSERT_TRUE(share.reserve("10.0.0.1", never, start));
  share.answered("10.0.0.1", std::string("lost.run1"));
  EXPECT_FALSE(share.reserve("10.0.0.1", never, start + 9min));
  EXPECT_TRUE(share.reserve("10.0.0.1", never, start + 10min));
}

TEST(AddressShare, ZeroIsNoCap) {
  AddressShare share(0, 1h);
  for (int k = 0; k < 100; ++k) EXPECT_TRUE(share.reserve("10.0.0.1", [](const std::string&) { return false; }));
}

}  // namespace
