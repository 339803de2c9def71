#include "progress.h"

namespace collision_lab {
namespace cli {

namespace {
constexpr std::chrono::seconds kQuietStart{1};
constexpr std::chrono::milliseconds kRedrawInterval{200};
}  // namespace

ProgressLine::ProgressLine(std::FILE* terminal, std::uint64_t expected)
    : terminal_(terminal), expected_(expected), start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

ProgressLine::~ProgressLine() {
  if (drawn_) {
    std::fputs("\r\033[K", terminal_);
    std::fflush(terminal_);
  }
}

void ProgressLine::maybeDraw(std::uint64_t index, double time) {
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < kQuietStart || now - last_draw_ < kRedrawInterval) return;
  last_draw_ = now;
  drawn_ = true;
  const double seconds = std::chrono::duration<double>(now - start_).count();
  if (expected_ == 0) {  // no count known in advance: the engine's impacts and time
    std::fprintf(terminal_, "\rcollision_lab_cli: %llu impacts, simulated t = %.6g s, %.3g impacts/s, %.1f s (Ctrl-C stops)\033[K",
                 static_cast<unsigned long long>(index), time, static_cast<double>(index) / seconds, seconds);
  } else {
    const double percent = 100.0 * static_cast<double>(index) / static_cast<double>(expected_);
    std::fprintf(terminal_, "\rcollision_lab_cli: %llu of %llu collisions (%.1f %%), %.1f s",
                 static_cast<unsigned long long>(index), static_cast<unsigned long long>(expected_), percent, seconds);
  }
  std::fflush(terminal_);
}

}  // namespace cli
}  // namespace collision_lab
