#pragma once
// Another program run with an argument vector and no shell: a name or path a user gave (an
// --out full of quotes or $(...)) reaches it as one argument and is never parsed as a command.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <vector>

namespace pbflow {

// Runs argv[0] (looked up on PATH where it has no '/') with `argv`, waits for it and returns
// its exit status: -1 where it could not be started or was killed. `quiet` sends its stdout
// and stderr to /dev/null.
inline int run_child(const std::vector<std::string>& argv, bool quiet = false) {
  if (argv.empty()) return -1;
  std::vector<std::string> args = argv;  // posix_spawn takes char*, not const char*
  std::vector<char*> pointers;
  for (std::string& a : args) pointers.push_back(a.data());
  pointers.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  }
  pid_t pid = -1;
  const int spawned = posix_spawnp(&pid, pointers[0], &actions, nullptr, pointers.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace pbflow
