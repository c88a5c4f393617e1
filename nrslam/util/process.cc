#include "nrslam/util/process.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <map>
#include <sstream>
#include <thread>

#include "nrslam/util/memory_usage.h"
#include "nrslam/util/text_file.h"

extern char** environ;

namespace nrslam {

std::string ProcessOutcome::Describe() const {
  if (!error.empty()) return error;
  if (interrupted) return "interrupted";
  if (timed_out_after_seconds > 0) {
    std::ostringstream text;
    text << "timed out after " << timed_out_after_seconds << " s (killed)";
    return text.str();
  }
  if (signal != 0) {
    std::string text = "killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
    if (peak_memory_mb > 0) text += " at a peak of " + std::to_string(std::lround(peak_memory_mb)) + " MB";
    return text;
  }
  return "exit code " + std::to_string(exit_code);
}

namespace {

// Starts one child with its output in `command.log`; returns its pid, or -1 with `error` set.
pid_t Start(const Command& command, std::string* error) {
  if (command.argv.empty()) {
    *error = "empty command";
    return -1;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string log = command.log.string();
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<char*> argv;
  for (const std::string& argument : command.argv) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int status = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (status != 0) {
    *error = "cannot start " + command.argv[0] + ": " + std::strerror(status);
    return -1;
  }
  return pid;
}

}  // namespace

std::vector<ProcessOutcome> RunCommands(const std::vector<Command>& commands, int jobs,
                                        const std::function<void(size_t, const ProcessOutcome&)>& done,
                                        const std::atomic<bool>* stop) {
  using Clock = std::chrono::steady_clock;
  struct Running {
    size_t index;
    Clock::time_point started;
    Clock::time_point deadline;  // Clock::time_point::max() without a timeout
  };
  std::vector<ProcessOutcome> outcomes(commands.size());
  std::map<pid_t, Running> running;
  size_t next = 0;
  const size_t limit = static_cast<size_t>(std::max(1, jobs));
  bool stopping = false;
  while (next < commands.size() || !running.empty()) {
    if (stop && *stop && !stopping) {
      stopping = true;
      for (const auto& [pid, child] : running) {
        outcomes[child.index].interrupted = true;
        kill(pid, SIGTERM);  // reaped below like any other ending
      }
      for (; next < commands.size(); ++next) {
        outcomes[next].interrupted = true;
        if (done) done(next, outcomes[next]);
      }
    }
    while (next < commands.size() && running.size() < limit) {
      const pid_t pid = Start(commands[next], &outcomes[next].error);
      if (pid < 0) {
        if (done) done(next, outcomes[next]);
      } else {
        const double timeout = commands[next].timeout_seconds;
        const Clock::time_point started = Clock::now();
        const Clock::time_point deadline =
            timeout > 0 ? started + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout))
                        : Clock::time_point::max();
        running[pid] = {next, started, deadline};
      }
      ++next;
    }
    if (running.empty()) continue;
    // Each child is reaped by its pid, never by wait(-1): the process may have other children
    // (another thread's batch, a caller's own), whose endings are not this call's to collect.
    bool any_ended = false;
    const Clock::time_point now = Clock::now();
    for (auto it = running.begin(); it != running.end();) {
      const auto [pid, child] = *it;
      ProcessOutcome& outcome = outcomes[child.index];
      int status = 0;
      rusage usage{};
      const pid_t ended = wait4(pid, &status, WNOHANG, &usage);
      if (ended == 0 || (ended < 0 && errno == EINTR)) {
        if (now >= child.deadline && outcome.timed_out_after_seconds == 0) {
          outcome.timed_out_after_seconds = commands[child.index].timeout_seconds;
          kill(pid, SIGKILL);  // reaped like any other ending
        }
        ++it;
        continue;
      }
      if (ended < 0) {
        outcome.error = "lost track of the child process";
      } else {
        if (WIFEXITED(status)) outcome.exit_code = WEXITSTATUS(status);
        if (WIFSIGNALED(status)) outcome.signal = WTERMSIG(status);
        outcome.peak_memory_mb = MaxResidentMb(usage);
      }
      outcome.wall_seconds = std::chrono::duration<double>(now - child.started).count();
      it = running.erase(it);
      any_ended = true;
      if (done) done(child.index, outcome);
    }
    if (!any_ended) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return outcomes;
}

std::optional<std::string> CommandOutput(const std::vector<std::string>& argv, double timeout_seconds) {
  static std::atomic<int> calls{0};
  const std::filesystem::path log = std::filesystem::temp_directory_path() /
                                    ("nrslam-output-" + std::to_string(getpid()) + "-" + std::to_string(calls++));
  const ProcessOutcome outcome = RunCommands({Command{argv, log, timeout_seconds}}, 1).front();
  std::string output = FileText(log);
  std::error_code ignored;
  std::filesystem::remove(log, ignored);
  if (!outcome.ok()) return std::nullopt;
  return output;
}

bool ProcessIsRunning(int pid) {
  if (pid <= 0 || (kill(pid, 0) != 0 && errno == ESRCH)) return false;
  // "pid (name) S ...": the state follows the last ')', as the name may hold any character.
  const std::string line = FileText("/proc/" + std::to_string(pid) + "/stat");
  const size_t name_end = line.rfind(')');
  return name_end == std::string::npos || name_end + 2 >= line.size() || line[name_end + 2] != 'Z';
}

std::string ShellLine(const std::vector<std::string>& argv) {
  std::string line;
  for (const std::string& argument : argv) {
    if (!line.empty()) line += ' ';
    const bool plain = !argument.empty() && argument.find_first_not_of(
        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=,:+@%") == std::string::npos;
    if (plain) {
      line += argument;
      continue;
    }
    line += '\'';
    for (char c : argument) line += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += '\'';
  }
  return line;
}

}  // namespace nrslam
