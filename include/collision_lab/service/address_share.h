// Each client address's bounded share of the lab (ROS-free, thread-safe): the runs it has
// sent and not seen finish, whatever student names it typed. One address under thirty
// names holds at most `per_address` places, so the fair scheduler's round robin cannot be
// filled by one machine.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <functional>
#include <iterator>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace collision_lab::service {

class AddressShare {
 public:
  using Clock = std::chrono::steady_clock;
  /// Whether run_id has ended (finished, stopped or interrupted).
  using Finished = std::function<bool(const std::string& run_id)>;

  /// per_address: places per address [1], 0 for no cap. A place whose run is never seen
  /// to end (its end missed) is given back after forget_after.
  AddressShare(std::size_t per_address, Clock::duration forget_after)
      : per_address_(per_address), forget_after_(forget_after) {}

  std::size_t perAddress() const { return per_address_; }

  /// Takes a place for a send from address; false when its places are all taken by
  /// unfinished runs (asked of `finished`, outside this object's lock: it may read a file).
  bool reserve(const std::string& address, const Finished& finished, Clock::time_point now = Clock::now()) {
    if (per_address_ == 0) return true;
    std::vector<std::string> runs;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      forgetLocked(now);
      const auto it = by_address_.find(address);
      if (it != by_address_.end()) {
        for (const Place& p : it->second) {
          if (!p.run_id.empty()) runs.push_back(p.run_id);
        }
      }
    }
    std::set<std::string> ended;
    for (const std::string& run_id : runs) {
      if (finished(run_id)) ended.insert(run_id);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Place>& places = by_address_[address];
    places.erase(std::remove_if(places.begin(), places.end(), [&](const Place& p) { return ended.count(p.run_id) > 0; }),
                 places.end());
    if (places.size() >= per_address_) return false;
    places.push_back(Place{std::string(), now});
    return true;
  }

  /// A reserved send's answer: the run it became, or nullopt (refused or unanswered: the
  /// place is given back).
  void answered(const std::string& address, const std::optional<std::string>& run_id) {
    if (per_address_ == 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = by_address_.find(address);
    if (it == by_address_.end()) return;
    std::vector<Place>& places = it->second;
    const auto sent = std::find_if(places.begin(), places.end(), [](const Place& p) { return p.run_id.empty(); });
    if (sent == places.end()) return;
    if (run_id) {
      sent->run_id = *run_id;
    } else {
      places.erase(sent);
    }
    if (places.empty()) by_address_.erase(it);
  }

  /// Places taken by address now [1] (sent, queued or running as last seen).
  std::size_t taken(const std::string& address) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = by_address_.find(address);
    return it == by_address_.end() ? 0 : it->second.size();
  }

 private:
  struct Place {
    std::string run_id;  ///< empty: sent, the lab's answer awaited
    Clock::time_point since;
  };
  /// Drops places older than forget_after_, and addresses left with none.
  void forgetLocked(Clock::time_point now) {
    for (auto it = by_address_.begin(); it != by_address_.end();) {
      std::vector<Place>& places = it->second;
      places.erase(std::remove_if(places.begin(), places.end(),
                                  [&](const Place& p) { return now - p.since >= forget_after_; }),
                   places.end());
      it = places.empty() ? by_address_.erase(it) : std::next(it);
    }
  }
  const std::size_t per_address_;
  const Clock::duration forget_after_;
  mutable std::mutex mutex_;
  std::map<std::string, std::vector<Place>> by_address_;  ///< addresses with places
};

}  // namespace collision_lab::service
