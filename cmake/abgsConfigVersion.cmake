# abgsConfigVersion.cmake: version check for find_package(abgs [version]).
#
# Compatibility is SameMajorVersion-style, except that while the major version
# is 0 a minor bump is a breaking change: 0.1.x satisfies a request for 0.1 or
# 0.1.y (y <= x) but neither 0.2 nor 0.0 (a bare `0` accepts any 0.x); 1.x
# satisfies any 1.y (y <= x). Version ranges (find_package(abgs 0.1...0.3)) are
# honoured as written.
#
# In the source tree the version is read from Cargo.toml's [workspace.package]
# `version`; scripts/install.sh hard-codes it on the next line when installing.
set(_abgs_hardcoded_version "")

if(_abgs_hardcoded_version)
  set(PACKAGE_VERSION "${_abgs_hardcoded_version}")
else()
  set(PACKAGE_VERSION "")
  set(_abgs_cargo_toml "${CMAKE_CURRENT_LIST_DIR}/../Cargo.toml")
  if(EXISTS "${_abgs_cargo_toml}")
    # Only section headers and `version = "..."` lines (keeps CMake's list
    # handling away from arbitrary TOML).
    file(STRINGS "${_abgs_cargo_toml}" _abgs_lines
         REGEX "^[ \t]*(\\[|version[ \t]*=)")
    set(_abgs_section "")
    foreach(_abgs_line IN LISTS _abgs_lines)
      if(_abgs_line MATCHES "^[ \t]*\\[([^]]*)\\]")
        string(STRIP "${CMAKE_MATCH_1}" _abgs_section)
      elseif(_abgs_section STREQUAL "workspace.package"
             AND _abgs_line MATCHES "^[ \t]*version[ \t]*=[ \t]*\"([^\"]+)\"")
        set(PACKAGE_VERSION "${CMAKE_MATCH_1}")
        break()
      endif()
    endforeach()
    unset(_abgs_lines)
    unset(_abgs_line)
    unset(_abgs_section)
  endif()
  unset(_abgs_cargo_toml)
endif()
unset(_abgs_hardcoded_version)

if(NOT PACKAGE_VERSION MATCHES "^([0-9]+)\\.([0-9]+)\\.([0-9]+)")
  # Neither installed nor next to a readable Cargo.toml: refuse rather than guess.
  set(PACKAGE_VERSION "unknown")
  set(PACKAGE_VERSION_UNSUITABLE TRUE)
  return()
endif()
set(_abgs_major "${CMAKE_MATCH_1}")
set(_abgs_minor "${CMAKE_MATCH_2}")

if(PACKAGE_FIND_VERSION_RANGE)
  # find_package(abgs MIN...MAX): within the range, as the caller wrote it.
  if(PACKAGE_VERSION VERSION_LESS PACKAGE_FIND_VERSION_MIN
     OR (PACKAGE_FIND_VERSION_RANGE_MAX STREQUAL "INCLUDE"
         AND PACKAGE_VERSION VERSION_GREATER PACKAGE_FIND_VERSION_MAX)
     OR (PACKAGE_FIND_VERSION_RANGE_MAX STREQUAL "EXCLUDE"
         AND PACKAGE_VERSION VERSION_GREATER_EQUAL PACKAGE_FIND_VERSION_MAX))
    set(PACKAGE_VERSION_COMPATIBLE FALSE)
  else()
    set(PACKAGE_VERSION_COMPATIBLE TRUE)
  endif()
elseif(NOT PACKAGE_FIND_VERSION)
  # find_package(abgs) with no version: anything goes.
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
elseif(PACKAGE_VERSION VERSION_LESS PACKAGE_FIND_VERSION)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
elseif(NOT PACKAGE_FIND_VERSION_MAJOR STREQUAL _abgs_major)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
elseif(_abgs_major STREQUAL "0"
       AND PACKAGE_FIND_VERSION_COUNT GREATER 1
       AND NOT PACKAGE_FIND_VERSION_MINOR EQUAL _abgs_minor)
  # 0.x: the minor version is the breaking one.
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
else()
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
endif()

if(PACKAGE_VERSION_COMPATIBLE AND PACKAGE_FIND_VERSION
   AND PACKAGE_FIND_VERSION VERSION_EQUAL PACKAGE_VERSION)
  set(PACKAGE_VERSION_EXACT TRUE)
endif()

unset(_abgs_major)
unset(_abgs_minor)
