# Writes OUTPUT (a .cc file defining ihs::app::BuildCommit()) with the commit of SOURCE_DIR
# (`git describe --always --dirty`, "unknown" outside a git checkout), and rewrites it only when
# that changes: one file recompiles after a commit, not every file that a definition would touch.
execute_process(
  COMMAND git -C "${SOURCE_DIR}" describe --always --dirty --abbrev=12
  OUTPUT_VARIABLE commit
  OUTPUT_STRIP_TRAILING_WHITESPACE
  RESULT_VARIABLE result
  ERROR_QUIET)
if(NOT result EQUAL 0 OR commit STREQUAL "")
  set(commit "unknown")
endif()
set(text "// Generated at build time by app/build_info.cmake.\n#include \"app/build_info.h\"\n\nnamespace ihs::app {\n\nconst char* BuildCommit() { return \"${commit}\"; }\n\n}  // namespace ihs::app\n")
set(old "")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUTPUT}" "${text}")
endif()
