#include "cli_process.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace collision_lab_test {

namespace {

std::string readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

/// runProgram, with stderr the slave side of a pseudo-terminal when `terminal` is true.
CliOutput runChild(const std::string& program_path, const std::vector<std::string>& args, const std::string& cwd,
                   const std::string& stdin_path, const std::string& stdout_path, bool terminal);

}  // namespace

CliOutput runCli(const std::vector<std::string>& args, const std::string& cwd, const std::string& stdin_path,
                 const std::string& stdout_path) {
  return runProgram(COLLISION_LAB_CLI_PATH, args, cwd, stdin_path, stdout_path);
}

CliOutput runCliOnTerminal(const std::vector<std::string>& args, const std::string& cwd) {
  return runChild(COLLISION_LAB_CLI_PATH, args, cwd, "/dev/null", "", true);
}

CliOutput runProgram(const std::string& program_path, const std::vector<std::string>& args, const std::string& cwd,
                     const std::string& stdin_path, const std::string& stdout_path) {
  return runChild(program_path, args, cwd, stdin_path, stdout_path, false);
}

namespace {

CliOutput runChild(const std::string& program_path, const std::vector<std::string>& args, const std::string& cwd,
                   const std::string& stdin_path, const std::string& stdout_path, bool terminal) {
  char dir_template[] = "/tmp/collision_lab_cli_test_XXXXXX";
  const char* dir = mkdtemp(dir_template);
  if (dir == nullptr) throw std::runtime_error("mkdtemp failed");
  const std::string out_path = std::string(dir) + "/stdout";
  const std::string err_path = std::string(dir) + "/stderr";

  std::vector<char*> argv;
  std::string program = program_path;
  argv.push_back(program.data());
  std::vector<std::string> owned(args);
  for (std::string& arg : owned) argv.push_back(arg.data());
  argv.push_back(nullptr);

  int master = -1;
  std::string slave_path;
  if (terminal) {
    master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0 || ptsname(master) == nullptr) {
      if (master >= 0) close(master);
      throw NoPseudoTerminal("no pseudo-terminal (is /dev/pts mounted?)");
    }
    slave_path = ptsname(master);
    const int slave = open(slave_path.c_str(), O_RDWR | O_NOCTTY);  // the child's stderr, tried first
    if (slave < 0) {
      close(master);
      throw NoPseudoTerminal("cannot open the pseudo-terminal " + slave_path + " (is /dev/pts mounted?)");
    }
    close(slave);
  }
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    const int in_fd = open(stdin_path.c_str(), O_RDONLY);
    const int out_fd = stdout_path.empty() ? open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600)
                                           : open(stdout_path.c_str(), O_WRONLY);
    const int err_fd = terminal ? open(slave_path.c_str(), O_RDWR | O_NOCTTY)
                                : open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (in_fd < 0 || out_fd < 0 || err_fd < 0 || dup2(in_fd, 0) < 0 || dup2(out_fd, 1) < 0 ||
        dup2(err_fd, 2) < 0 || chdir(cwd.c_str()) != 0) {
      _exit(126);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  CliOutput result;
  if (terminal) {  // drain the terminal while the child runs, so that it never blocks on it
    char buffer[4096];
    for (;;) {
      pollfd watched{master, POLLIN, 0};
      if (poll(&watched, 1, 100) > 0) {
        const ssize_t n = read(master, buffer, sizeof buffer);
        if (n > 0) {
          result.err.append(buffer, static_cast<std::size_t>(n));
        } else if (n == 0 || errno != EINTR) {
          break;  // EIO: the child closed the terminal
        }
      } else {
        siginfo_t exited{};
        if (waitid(P_PID, static_cast<id_t>(pid), &exited, WEXITED | WNOHANG | WNOWAIT) == 0 && exited.si_pid == pid) break;
      }
    }
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("waitpid failed");
  }
  if (terminal) close(master);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (stdout_path.empty()) result.out = readWhole(out_path);
  if (!terminal) result.err = readWhole(err_path);
  unlink(out_path.c_str());
  unlink(err_path.c_str());
  rmdir(dir);
  return result;
}

}  // namespace

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace collision_lab_test
