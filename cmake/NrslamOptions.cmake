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

# Developers' check for memory errors and undefined behaviour, e.g.
#   cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNRSLAM_SANITIZE=address,undefined
# Every target of this project is instrumented (the Debian libraries are not); a finding
# aborts the program, so CTest reports it as a failed test.
set(NRSLAM_SANITIZE "" CACHE STRING "sanitizers to build with (-fsanitize=...), e.g. address,undefined; empty: none")
if(NRSLAM_SANITIZE)
  add_compile_options(-fsanitize=${NRSLAM_SANITIZE} -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_link_options(-fsanitize=${NRSLAM_SANITIZE})
endif()
