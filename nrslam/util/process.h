// util: running other programs as child processes, a few at a time.
//
// The batch evaluator runs every sequence in its own process so that one sequence that
// crashes or runs out of memory cannot take the others down, and so that runs on many
// cores share nothing.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace nrslam {

struct Command {
  std::vector<std::string> argv;  // argv[0] is the program's path
  std::filesystem::path log;      // receives the child's stdout and stderr (truncated first)
  double timeout_seconds = 0;     // wall clock after which the child is killed (SIGKILL); 0: none
};

struct ProcessOutcome {
  int exit_code = -1;  // when the child exited
  int signal = 0;      // when a signal ended it
  std::string error;   // when it could not be started
  double timed_out_after_seconds = 0;  // when it was killed for running past its timeout
  bool interrupted = false;   // the batch was stopped: never started, or ended by SIGTERM
  double peak_memory_mb = 0;  // the child's peak resident memory, once it has ended
  double wall_seconds = 0;    // how long it ran, from its start to its end (wall clock)
  bool ok() const {
    return error.empty() && signal == 0 && exit_code == 0 && timed_out_after_seconds == 0 && !interrupted;
  }
  // "exit code 1", "killed by signal 9 (Killed) at a peak of 23112 MB", "timed out after 60 s
  // (killed)", "interrupted", or the start error. The peak says whether a killed run was out
  // of memory.
  std::string Describe() const;
};

// Runs the commands, at most `jobs` at once, in order of index; `done` is called (on this
// thread) as each one finishes. Never throws for a child's failure: that is its outcome. It
// collects only its own children, so calls in several threads at once do not mix them up.
// Once `*stop` is true (e.g. set by a SIGTERM handler) no further command starts, those
// running are sent SIGTERM and waited for, and every one of them is `interrupted`.
std::vector<ProcessOutcome> RunCommands(const std::vector<Command>& commands, int jobs,
                                        const std::function<void(size_t index, const ProcessOutcome&)>& done = {},
                                        const std::atomic<bool>* stop = nullptr);

// Runs a command to its end and returns what it wrote (stdout and stderr); nullopt when it
// could not be started, did not exit with 0 or ran past the timeout (then it is killed). For
// short queries such as a program's --version, not for runs.
std::optional<std::string> CommandOutput(const std::vector<std::string>& argv, double timeout_seconds);

// Whether a process of this machine is still running: false once it has ended, even while it
// waits to be reaped (a zombie).
bool ProcessIsRunning(int pid);

// A command as one line a POSIX shell runs as is (every argument single-quoted as needed).
std::string ShellLine(const std::vector<std::string>& argv);

}  // namespace nrslam
