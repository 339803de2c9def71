#include "node_text.h"

#include <ctime>
#include <sstream>

namespace collision_lab_ros {

// gmtime_r, not std::gmtime's shared buffer: the service threads call it concurrently.
std::string utcStamp(const char* format) {
  char buffer[32];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(buffer, sizeof buffer, format, &utc);
  return buffer;
}

std::string predictedText(const collision_lab::RunSummary& summary) {
  std::ostringstream text;
  if (summary.predicted_collision_count_defined) {
    text << "predicted " << summary.predicted_collision_count;
  } else if (summary.infinite_collisions) {
    text << "predicted: infinitely many collisions (" << summary.model_name << ")";
  } else {
    text << "no count predicted by " << summary.model_name;
  }
  if (summary.collapsed) text << ", collapsed at t = " << summary.collapse_time << " s";
  return text.str();
}

}  // namespace collision_lab_ros
