// util: the error type of nrslam.
//
// Library code reports bad input (a broken sequence, an invalid option) by throwing
// nrslam::Error with a message a user can act on. Programs catch it at the top and exit
// non-zero; batch runners record it and go on with the next sequence.
#pragma once

#include <stdexcept>
#include <string>

namespace nrslam {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace nrslam
