# Script mode (cmake -P), run at every build by the nrslam_source_revision target: writes
# OUTPUT from TEMPLATE with @revision@ = the git commit of SOURCE_DIR (12 hex digits), followed
# by "-dirty-" and 8 hex digits of a hash of `git diff HEAD` when tracked files have uncommitted
# changes (so two different sets of edits get different names); "unknown" outside a git
# checkout or without git. configure_file rewrites OUTPUT only when its text changes, so an
# unchanged tree rebuilds nothing.
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
configure_file("${TEMPLATE}" "${OUTPUT}" @ONLY)
