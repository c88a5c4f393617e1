// util: the progress line the command-line tools print on stderr while they work.
//
// On a terminal the line is rewritten in place. Into a file or a pipe (`2> run.log`, a Slurm
// or GNU parallel log) carriage returns would pile every update onto one enormous line, so
// there each update that is printed gets a line of its own: the first, then at most one per
// `interval_s`, and always the last.
#pragma once

#include <chrono>
#include <iosfwd>
#include <string>

namespace nrslam {

class ProgressLine {
 public:
  // in_place: rewrite one line (a terminal) or print whole lines (anything else).
  ProgressLine(std::ostream& out, bool in_place, double interval_s);
  // Stderr, in place exactly when stderr is a terminal, a line every 10 s otherwise.
  static ProgressLine OnStderr();

  // `last` ends the line (in place) or forces it out (whole lines).
  void Update(const std::string& line, bool last);

 private:
  std::ostream& out_;
  bool in_place_;
  std::chrono::duration<double> interval_;
  bool printed_any_ = false;
  std::chrono::steady_clock::time_point last_printed_;
  size_t previous_width_ = 0;  // in place: columns a shorter line must blank out
};

}  // namespace nrslam
