#include "collision_lab/ros/run_ids.h"

#include "collision_lab/service/envelope.h"

namespace collision_lab_ros {

std::string requestedRunId(const collision_lab::InitialConditions& input) {
  return collision_lab::service::requestedRunId(input.student, input.run_id);
}

}  // namespace collision_lab_ros
