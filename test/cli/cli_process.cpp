#include "cli_process.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
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

}  // namespace

CliOutput runCli(const std::vector<std::string>& args, const std::string& cwd, const std::string& stdin_path,
                 const std::string& stdout_path) {
  return runProgram(COLLISION_LAB_CLI_PATH, args, cwd, stdin_path, stdout_path);
}

CliOutput runProgram(const std::string& program_path, const std::vector<std::string>& args, const std::string& cwd,
                     const std::string& stdin_path, const std::string& stdout_path) {
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

  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    const int in_fd = open(stdin_path.c_str(), O_RDONLY);
    const int out_fd = stdout_path.empty() ? open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600)
                                           : open(stdout_path.c_str(), O_WRONLY);
    const int err_fd = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (in_fd < 0 || out_fd < 0 || err_fd < 0 || dup2(in_fd, 0) < 0 || dup2(out_fd, 1) < 0 ||
        dup2(err_fd, 2) < 0 || chdir(cwd.c_str()) != 0) {
      _exit(126);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("waitpid failed");
  }
  CliOutput result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (stdout_path.empty()) result.out = readWhole(out_path);
  result.err = readWhole(err_path);
  unlink(out_path.c_str());
  unlink(err_path.c_str());
  rmdir(dir);
  return result;
}

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace collision_lab_test
