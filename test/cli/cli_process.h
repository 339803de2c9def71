// Runs the built collision_lab_cli as a child process and captures what it prints.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace collision_lab_test {

struct CliOutput {
  int exit_code = -1;  ///< the exit status, or 128 + signal number if it was killed
  std::string out;
  std::string err;
};

/// Runs COLLISION_LAB_CLI_PATH with `args` in the working directory `cwd`, stdin from
/// `stdin_path` (default /dev/null), stdout and stderr into unique temporary files, or
/// stdout into `stdout_path` when given (then `out` stays empty).
CliOutput runCli(const std::vector<std::string>& args, const std::string& cwd,
                 const std::string& stdin_path = "/dev/null", const std::string& stdout_path = "");

/// As runCli, but runs the executable `program` (e.g. a copy of the CLI elsewhere).
CliOutput runProgram(const std::string& program, const std::vector<std::string>& args, const std::string& cwd,
                     const std::string& stdin_path = "/dev/null", const std::string& stdout_path = "");

/// Thrown by runCliOnTerminal where the system has no pseudo-terminals (a chroot without
/// /dev/pts mounted, as the fresh-Debian check's).
struct NoPseudoTerminal : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// As runCli, with stderr a pseudo-terminal (where the CLI draws its progress line);
/// `err` holds what was written there.
CliOutput runCliOnTerminal(const std::vector<std::string>& args, const std::string& cwd);

/// The lines of `text` (a final newline does not start another line).
std::vector<std::string> linesOf(const std::string& text);

}  // namespace collision_lab_test
