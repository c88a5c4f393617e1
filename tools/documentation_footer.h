// tools: the line each program's --help ends with, naming the docs pages that describe it and
// where those pages are, in a checkout and in an installation (cmake/NrslamInstall.cmake).
#pragma once

#include <string>

inline std::string DocumentationFooter(const std::string& pages) {
  return "Documentation: " + pages +
         ". docs/ is in the source tree and, once installed, in <prefix>/share/doc/nrslam/.";
}
