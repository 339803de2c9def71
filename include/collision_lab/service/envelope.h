// The envelope of a run (ROS-free): what every input must be before the lab plans its
// scene, checked by one function wherever a run comes in (the lab node's topic and
// services, the web's POST /api/runs), so that both refuse the same inputs with the same
// words. The scene itself is the core's to judge (core::planScene).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace collision_lab::service {

/// A student's name: at most this many characters.
constexpr std::size_t kMaxStudentLength = 64;

/// Empty when run_id is safe as a bag file name; otherwise why not.
std::string runIdProblem(const std::string& run_id);
/// Empty when student is a valid student name (empty is: anonymous); otherwise why not.
std::string studentProblem(const std::string& student);
/// The run_id an input asks for: <student>.<run_id>, <student> when it names no run_id, or
/// run_id when it names no student (empty: the lab assigns one).
std::string requestedRunId(const std::string& student, const std::string& run_id);

/// What the envelope looks at in an input.
struct EnvelopeInput {
  std::string student;     ///< empty: anonymous
  std::string run_id;      ///< as asked, without the student; empty: the lab assigns one
  std::uint64_t mode = 0;  ///< 0 full, 1 predict only, 2 summary only (InitialConditions.MODE_*)
  std::size_t bodies = 0;  ///< [1] the longest of the scene's masses, positions, velocities
};

struct EnvelopeRefusal {
  enum class Reason { kInvalidStudent, kInvalidRunId, kInvalidMode, kTooManyBodies };
  Reason reason;
  std::string field;    ///< the input's field: "student", "run_id", "mode" or "masses"
  std::string message;  ///< why, with the limit and what to do
};

/// Why input is outside the envelope of a lab that takes at most max_bodies bodies, if it
/// is: the student, the run_id (as asked, then as served), the mode, then the size.
std::optional<EnvelopeRefusal> checkEnvelope(const EnvelopeInput& input, std::size_t max_bodies);

}  // namespace collision_lab::service
