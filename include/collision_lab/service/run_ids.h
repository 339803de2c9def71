// Which run_id a run is served under (ROS-free): the one it asks for when nothing holds it,
// else the next free one, and a fresh one when it asks for none. What holds a run_id
// besides this lab's own memory (the run index, the bag folder) is the Ledger's to say.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>

namespace collision_lab::service {

/// A numbered run, "run<n>" or "<prefix>.run<n>" (the web node numbers each student's runs
/// so): its name up to the number ("ben.run") and n; nullopt for any other run_id.
std::optional<std::pair<std::string, std::uint64_t>> numberedRunId(const std::string& run_id);

/// A bounded memory of run_ids given out (the newest `capacity`), so that a long-running
/// lab stays flat in memory; with recording on, the bag folder remembers every run_id anyway.
class RememberedRunIds {
 public:
  explicit RememberedRunIds(std::size_t capacity) : capacity_(capacity) {}
  bool contains(const std::string& run_id) const { return ids_.count(run_id) > 0; }
  void add(const std::string& run_id);

 private:
  std::size_t capacity_;
  std::unordered_set<std::string> ids_;
  std::deque<std::string> order_;  ///< oldest first
};

/// Claims run_ids for a lab's runs. Not thread-safe: the owner locks.
class RunIdClaims {
 public:
  struct Ledger {
    /// The run index lists run_id (served by this lab or an earlier one).
    std::function<bool(const std::string& run_id)> served_before;
    /// A run of the run index holds run_id: it has not ended, or its bag is on disk.
    std::function<bool(const std::string& run_id)> held;
    /// Takes run_id's bag for this lab (when recording); false when another has it. May set
    /// error (the bag could not be claimed for another reason: the run goes unrecorded).
    std::function<bool(const std::string& run_id, std::string& error)> take_bag;
  };

  /// Fresh run_ids are <prefix><counter>, from 1.
  RunIdClaims(std::string prefix, std::size_t remembered, Ledger ledger);

  /// Takes run_id: false when this lab gave it out recently or take_bag refuses it.
  bool claim(const std::string& run_id, std::string& error);
  /// The first fresh run_id claim() takes.
  std::string fresh(std::string& error);
  /// requested, or the first requested.N (N = 2, 3, ...) that claim() takes and the index
  /// does not hold. A student's n-th run (<student>.run<n>) goes on to the first number
  /// that claim() takes and the run index has never served.
  std::string claimAsked(const std::string& requested, std::string& error);

 private:
  std::string prefix_;
  std::uint64_t counter_ = 0;
  RememberedRunIds given_;
  Ledger ledger_;
};

}  // namespace collision_lab::service
