# Script mode (cmake -P), run at every build by the nrslam_source_revision target: writes
# OUTPUT from TEMPLATE with two names for the code being built.
#
# @revision@, for people: the git commit of SOURCE_DIR (12 hex digits), followed by "-dirty-"
# and 8 hex digits of a hash of `git diff HEAD` when tracked files have uncommitted changes
# (so two different sets of edits get different names); "unknown" outside a git checkout or
# without git.
#
# @code_fingerprint@, for deciding whether a finished run can be reused: 12 hex digits of a
# SHA-1 over the contents of every file that decides what a run computes (the library, the
# tools, the build scripts) and over BUILD_FLAVOUR (compiler, flags, and the versions of Eigen,
# Ceres, OpenCV and Embree). A commit that only touches the README, the tests or a manifest
# keeps it, so it does not throw away finished runs; it needs no git, so a copy of the sources
# without .git still resumes safely.
#
# configure_file rewrites OUTPUT only when its text changes, so an unchanged tree rebuilds
# nothing.
execute_process(COMMAND git -C "${SOURCE_DIR}" rev-parse --short=12 HEAD
                OUTPUT_VARIABLE revision RESULT_VARIABLE failed OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(failed OR revision STREQUAL "")
  set(revision "unknown")
else()
  execute_process(COMMAND git -C "${SOURCE_DIR}" diff HEAD OUTPUT_VARIABLE changes ERROR_QUIET)
  if(NOT changes STREQUAL "")
    string(SHA1 changes_hash "${changes}")
    string(SUBSTRING "${changes_hash}" 0 8 changes_hash)
    string(APPEND revision "-dirty-${changes_hash}")
  endif()
endif()

# 12 hex digits of a SHA-1 over BUILD_FLAVOUR and the contents of FILES (relative to
# SOURCE_DIR), into VARIABLE.
function(fingerprint variable files)
  list(SORT files)
  set(listing "${BUILD_FLAVOUR}\n")
  foreach(file IN LISTS files)
    file(SHA1 "${SOURCE_DIR}/${file}" file_hash)
    string(APPEND listing "${file} ${file_hash}\n")
  endforeach()
  string(SHA1 hash "${listing}")
  string(SUBSTRING "${hash}" 0 12 hash)
  set(${variable} "${hash}" PARENT_SCOPE)
endfunction()

file(GLOB_RECURSE code_files LIST_DIRECTORIES false RELATIVE "${SOURCE_DIR}"
     "${SOURCE_DIR}/nrslam/*.h" "${SOURCE_DIR}/nrslam/*.cc" "${SOURCE_DIR}/nrslam/*.in"
     "${SOURCE_DIR}/nrslam/CMakeLists.txt" "${SOURCE_DIR}/tools/*.h" "${SOURCE_DIR}/tools/*.cc"
     "${SOURCE_DIR}/tools/CMakeLists.txt" "${SOURCE_DIR}/cmake/*.cmake")
list(APPEND code_files CMakeLists.txt)
fingerprint(code_fingerprint "${code_files}")

# @sequence_code_fingerprint@, for deciding whether a rendered or imported sequence in the
# cache can be reused: the same over the code that makes sequences (the simulator, the
# importers and the folders they build on, and their two tools).
set(sequence_code_globs "${SOURCE_DIR}/tools/nrslam_simulate.cc" "${SOURCE_DIR}/tools/nrslam_import.cc")
foreach(folder IN ITEMS sim datasets io camera geometry util)
  list(APPEND sequence_code_globs "${SOURCE_DIR}/nrslam/${folder}/*.h" "${SOURCE_DIR}/nrslam/${folder}/*.cc"
       "${SOURCE_DIR}/nrslam/${folder}/*.in")
endforeach()
file(GLOB sequence_code_files LIST_DIRECTORIES false RELATIVE "${SOURCE_DIR}" ${sequence_code_globs})
fingerprint(sequence_code_fingerprint "${sequence_code_files}")

configure_file("${TEMPLATE}" "${OUTPUT}" @ONLY)
