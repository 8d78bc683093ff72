# The source revision a build is made from (thz_revision(), `thzmap --version`,
# summary.json's and batch.json's `thzmap_revision`): the version alone, 0.1.0, names no
# commit between releases, so an output could not be traced to the code that made it.
#
# The revision is the git commit of the source directory, 40 hex digits, with "-dirty"
# appended when a tracked file differs from it (staged or not; untracked files do not
# count). It is asked of git at every build, not only at configure time: a commit or an
# edit after `cmake -S . -B build` shows in the next `cmake --build`. "unknown" when the
# source directory is not the top of a git checkout (an unpacked archive, also one
# unpacked inside another repository) or git is missing; the build goes on. A packager
# building from an archive gives the revision with -DTHZ_REVISION=... (letters, digits
# and . _ + ~ : / -), which git is then not asked for.
#
# Included by CMakeLists.txt, this file defines the target thzmap_revision, which runs
# this same file as a script (cmake -P) at every build. The script writes
# BUILD/generated/thz_revision.c, the definition of thz_revision(), only when its content
# changes (Ninja's restat then leaves the library alone when nothing changed).

if(CMAKE_SCRIPT_MODE_FILE)
  # ---- the script: -DSOURCE_DIR=... -DOUTPUT=... [-DREVISION=...] ----------------------
  cmake_minimum_required(VERSION 3.20) # the policies of CMakeLists.txt's, in cmake -P too
  set(revision "unknown")
  if(REVISION)
    set(revision "${REVISION}")
  else()
    find_program(git_program git)
    if(git_program)
      # The repository's own: no GIT_DIR, work tree or index from a calling git (a hook).
      unset(ENV{GIT_DIR})
      unset(ENV{GIT_WORK_TREE})
      unset(ENV{GIT_INDEX_FILE})
      # A checkout owned by another user (the set-up run as root on one's clone) is
      # trusted: the build already runs its CMakeLists.txt. No fsmonitor hook is run;
      # --no-optional-locks: `git status` refreshes the index without writing it, so
      # that a build never holds .git/index.lock against the user's own git.
      set(git ${git_program} -c safe.directory=${SOURCE_DIR} -c core.fsmonitor=false
          --no-optional-locks -C ${SOURCE_DIR})
      execute_process(COMMAND ${git} rev-parse --show-toplevel HEAD
        RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_QUIET OUTPUT_STRIP_TRAILING_WHITESPACE)
      if(rc EQUAL 0)
        string(REPLACE "\n" ";" out "${out}")
        list(LENGTH out n)
        if(n EQUAL 2)
          list(GET out 0 top)
          list(GET out 1 commit)
          file(REAL_PATH "${top}" top)
          file(REAL_PATH "${SOURCE_DIR}" source)
          if(top STREQUAL source AND commit MATCHES "^[0-9a-f]+$")
            execute_process(COMMAND ${git} status --porcelain --untracked-files=no
              RESULT_VARIABLE rc OUTPUT_VARIABLE changes ERROR_QUIET)
            if(rc EQUAL 0)
              set(revision "${commit}")
              if(NOT changes STREQUAL "")
                string(APPEND revision "-dirty")
              endif()
            endif()
          endif()
        endif()
      endif()
    endif()
  endif()
  string(CONFIGURE [[
/* Written by cmake/revision.cmake at every build: the source revision built.
 * Not part of the repository; do not edit. */
#include "thzmap/thzmap.h"

const char *thz_revision(void)
{
    return "@revision@";
}
]] content @ONLY)
  set(old "")
  if(EXISTS "${OUTPUT}")
    file(READ "${OUTPUT}" old)
  endif()
  if(NOT old STREQUAL content)
    file(WRITE "${OUTPUT}" "${content}")
  endif()
  return()
endif()

# ---- the target ----------------------------------------------------------------------
set(THZ_REVISION "" CACHE STRING
  "The source revision thzmap reports (default: git's commit at every build, else unknown)")
if(NOT THZ_REVISION STREQUAL "" AND NOT THZ_REVISION MATCHES "^[A-Za-z0-9._+~:/-]+$")
  message(FATAL_ERROR "THZ_REVISION='${THZ_REVISION}': expected letters, digits and "
    ". _ + ~ : / - only (e.g. a commit or a package version)")
endif()
set(THZ_REVISION_SOURCE ${CMAKE_BINARY_DIR}/generated/thz_revision.c)
# No OUTPUT: a custom target is always out of date, so the script runs at every build;
# BYPRODUCTS tells Ninja which target makes the file the library compiles.
add_custom_target(thzmap_revision
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${CMAKE_SOURCE_DIR} -DOUTPUT=${THZ_REVISION_SOURCE}
          -DREVISION=${THZ_REVISION} -P ${CMAKE_CURRENT_LIST_FILE}
  BYPRODUCTS ${THZ_REVISION_SOURCE}
  COMMENT "thzmap: the source revision (git)"
  VERBATIM)
target_sources(thzmap_objects PRIVATE ${THZ_REVISION_SOURCE})
add_dependencies(thzmap_objects thzmap_revision)
