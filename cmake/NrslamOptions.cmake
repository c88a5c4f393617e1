# Compiler flags shared by every nrslam target.
#
# Release keeps -O2 (not -O3) so that the tests run the same optimised code the users run,
# at a compile time the 2-core CI machine can afford.
set(CMAKE_CXX_FLAGS_RELEASE "-O2 -DNDEBUG")
set(CMAKE_CXX_FLAGS_RELWITHDEBINFO "-O2 -g -DNDEBUG")

add_library(nrslam_warnings INTERFACE)
target_compile_options(nrslam_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual
  -Wno-unused-parameter)
