#include "collision_lab/ros/run_ids.h"

#include "collision_lab/ros/node_constants.h"

namespace collision_lab_ros {

std::string runIdProblem(const std::string& run_id) {
  if (run_id.size() > 200) return "is longer than 200 characters";
  if (run_id.empty() || run_id[0] == '.') return "must not be empty or start with '.'";
  for (char c : run_id) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                      (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!safe) return "may contain only letters, digits, '_', '-' and '.'";
  }
  return {};
}

std::string studentProblem(const std::string& student) {
  if (student.size() > kMaxStudentLength) {
    return "is longer than " + std::to_string(kMaxStudentLength) + " characters";
  }
  for (char c : student) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!safe) return "may contain only letters, digits, '_' and '-' ('.' separates it from the run_id)";
  }
  return {};
}

std::optional<std::pair<std::string, std::uint64_t>> numberedRunId(const std::string& run_id) {
  const std::size_t digits = run_id.find_last_not_of("0123456789") + 1;
  if (digits == run_id.size() || run_id.size() - digits > 18) return std::nullopt;
  if (digits < 3 || run_id.compare(digits - 3, 3, "run") != 0) return std::nullopt;
  if (digits > 3 && run_id[digits - 4] != '.') return std::nullopt;
  return std::make_pair(run_id.substr(0, digits), std::stoull(run_id.substr(digits)));
}

std::string requestedRunId(const collision_lab::InitialConditions& input) {
  if (input.student.empty()) return input.run_id;
  return input.run_id.empty() ? input.student : input.student + "." + input.run_id;
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
