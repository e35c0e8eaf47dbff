# Writes OUT, a header defining MASA_GIT_COMMIT (git describe of SOURCE_DIR, "-dirty" with
# uncommitted changes, "unknown" outside a checkout). Run at every build; the file is replaced only
# when the commit changed, so that only its includers recompile then.
execute_process(COMMAND git -C "${SOURCE_DIR}" describe --always --dirty --abbrev=12
                OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR commit STREQUAL "")
  set(commit unknown)
endif()
file(WRITE "${OUT}.tmp" "#pragma once\n#define MASA_GIT_COMMIT \"${commit}\"\n")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUT}.tmp")
