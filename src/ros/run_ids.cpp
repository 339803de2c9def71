#include "collision_lab/ros/run_ids.h"

#include "collision_lab/ros/node_constants.h"
#include "collision_lab/service/envelope.h"

namespace collision_lab_ros {

std::optional<std::pair<std::string, std::uint64_t>> numberedRunId(const std::string& run_id) {
  const std::size_t digits = run_id.find_last_not_of("0123456789") + 1;
  if (digits == run_id.size() || run_id.size() - digits > 18) return std::nullopt;
  if (digits < 3 || run_id.compare(digits - 3, 3, "run") != 0) return std::nullopt;
  if (digits > 3 && run_id[digits - 4] != '.') return std::nullopt;
  return std::make_pair(run_id.substr(0, digits), std::stoull(run_id.substr(digits)));
}

std::string requestedRunId(const collision_lab::InitialConditions& input) {
  return collision_lab::service::requestedRunId(input.student, input.run_id);
}

void RememberedRunIds::add(const std::string& run_id) {
  if (!ids_.insert(run_id).second) return;
  order_.push_back(run_id);
  if (order_.size() > kRunIdsRemembered) {
    ids_.erase(order_.front());
    order_.pop_front();
  }
}

}  // namespace collision_lab_ros
