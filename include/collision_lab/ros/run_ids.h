// Run ids: the one an input asks for, a student's numbered runs, and a bounded memory of
// those given out (which are safe as bag names: service/envelope.h).
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>

#include "collision_lab/InitialConditions.h"

namespace collision_lab_ros {

/// The run_id an input asks for (service::requestedRunId). A taken one is then served as
/// <that>.N, except a numbered run (numberedRunId): that one as the next free number.
std::string requestedRunId(const collision_lab::InitialConditions& input);
/// A numbered run, "run<n>" or "<prefix>.run<n>" (the web node numbers each student's runs
/// so): its name up to the number ("ben.run") and n; nullopt for any other run_id.
std::optional<std::pair<std::string, std::uint64_t>> numberedRunId(const std::string& run_id);

/// A bounded memory of run_ids given out (the newest kRunIdsRemembered), so that a
/// long-running node stays flat in memory; with recording on, the bag folder remembers
/// every run_id anyway (claimBag).
class RememberedRunIds {
 public:
  bool contains(const std::string& run_id) const { return ids_.count(run_id) > 0; }
  void add(const std::string& run_id);

 private:
  std::unordered_set<std::string> ids_;
  std::deque<std::string> order_;  ///< oldest first
};

}  // namespace collision_lab_ros
