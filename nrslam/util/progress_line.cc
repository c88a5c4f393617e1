#include "nrslam/util/progress_line.h"

#include <unistd.h>

#include <iostream>

#include "nrslam/util/text_table.h"

namespace nrslam {

ProgressLine::ProgressLine(std::ostream& out, bool in_place, double interval_s)
    : out_(out), in_place_(in_place), interval_(interval_s) {}

ProgressLine ProgressLine::OnStderr() { return ProgressLine(std::cerr, isatty(STDERR_FILENO) == 1, 10.0); }

void ProgressLine::Update(const std::string& line, bool last) {
  if (in_place_) {
    out_ << '\r' << line;
    const size_t width = DisplayWidth(line);  // a name with "ü" takes fewer columns than bytes
    if (width < previous_width_) out_ << std::string(previous_width_ - width, ' ');
    previous_width_ = width;
    if (last) {
      out_ << '\n';
      previous_width_ = 0;
    }
    out_ << std::flush;
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  if (!last && printed_any_ && now - last_printed_ < interval_) return;
  out_ << line << '\n' << std::flush;
  printed_any_ = true;
  last_printed_ = now;
}

}  // namespace nrslam
