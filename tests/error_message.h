// Tests: the message of the nrslam::Error a call throws, or "" when it throws none, so that a
// test can check that a mistake is named.
#pragma once

#include <string>

#include "nrslam/util/error.h"

namespace nrslam {

template <typename Call>
std::string ErrorMessage(Call&& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace nrslam
