#include "collision_lab/service/envelope.h"

namespace collision_lab::service {

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

std::string requestedRunId(const std::string& student, const std::string& run_id) {
  if (student.empty()) return run_id;
  return run_id.empty() ? student : student + "." + run_id;
}

std::optional<EnvelopeRefusal> checkEnvelope(const EnvelopeInput& input, std::size_t max_bodies) {
  using Reason = EnvelopeRefusal::Reason;
  if (const std::string problem = studentProblem(input.student); !problem.empty()) {
    // A name over the length is not echoed: it may be kilobytes.
    const bool echo = input.student.size() <= kMaxStudentLength;
    return EnvelopeRefusal{Reason::kInvalidStudent, "student",
                           (echo ? "student '" + input.student + "' " : std::string("student ")) + problem};
  }
  if (!input.run_id.empty()) {
    if (const std::string problem = runIdProblem(input.run_id); !problem.empty()) {
      return EnvelopeRefusal{Reason::kInvalidRunId, "run_id", "run_id '" + input.run_id + "' " + problem};
    }
  }
  if (const std::string served = requestedRunId(input.student, input.run_id); !input.student.empty()) {
    if (const std::string problem = runIdProblem(served); !problem.empty()) {
      return EnvelopeRefusal{Reason::kInvalidRunId, "run_id", "run_id '" + served + "' (<student>.<run_id>) " + problem};
    }
  }
  if (input.mode > 2) {
    return EnvelopeRefusal{Reason::kInvalidMode, "mode",
                           "mode " + std::to_string(input.mode) +
                               " is not one of MODE_FULL (0), MODE_PREDICT_ONLY (1), MODE_SUMMARY_ONLY (2)"};
  }
  if (input.bodies > max_bodies) {
    return EnvelopeRefusal{Reason::kTooManyBodies, "masses",
                           std::to_string(input.bodies) + " bodies are more than this node's ~max_bodies = " +
                               std::to_string(max_bodies) +
                               "; send a smaller scene, or start the node with a larger ~max_bodies"};
  }
  return std::nullopt;
}

}  // namespace collision_lab::service
