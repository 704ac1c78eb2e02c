# abgsConfig.cmake: package configuration for find_package(abgs).
#
# Defines
#   abgs::abgs         the shared library libabgs.so (SHARED IMPORTED)
#   abgs::abgs_static  the static library libabgs.a (STATIC IMPORTED), when present
# and sets abgs_INCLUDE_DIR, abgs_LIBRARY, abgs_STATIC_LIBRARY.
#
# Works in two layouts:
#   source tree  <repo>/cmake/abgsConfig.cmake, with <repo>/include/abgs.h and the
#                library from `cargo build --release --lib` in <repo>/target/release
#                (else <repo>/target/debug). Use: -Dabgs_DIR=<repo>/cmake.
#   installed    <prefix>/lib/cmake/abgs/abgsConfig.cmake, with <prefix>/include/abgs.h
#                and <prefix>/lib/libabgs.so (scripts/install.sh <prefix>).
#                Use: -DCMAKE_PREFIX_PATH=<prefix>.
# In either layout, the cache variable ABGS_LIBRARY_DIR (a directory holding
# libabgs.so / libabgs.a) overrides where the library is taken from.

cmake_policy(PUSH)
cmake_policy(VERSION 3.12...3.31)

set(_abgs_here "${CMAKE_CURRENT_LIST_DIR}")

if(EXISTS "${_abgs_here}/../Cargo.toml" AND EXISTS "${_abgs_here}/../include/abgs.h")
  # Source tree.
  get_filename_component(_abgs_root "${_abgs_here}/.." ABSOLUTE)
  set(abgs_INCLUDE_DIR "${_abgs_root}/include")
  set(ABGS_LIBRARY_DIR "" CACHE PATH
      "Directory holding libabgs.so and libabgs.a (empty: <repo>/target/release, else <repo>/target/debug)")
  if(ABGS_LIBRARY_DIR)
    set(_abgs_libdirs "${ABGS_LIBRARY_DIR}")
  else()
    set(_abgs_libdirs "${_abgs_root}/target/release" "${_abgs_root}/target/debug")
  endif()
  set(_abgs_hint "build it with `cargo build --release --lib` in ${_abgs_root}")
else()
  # Installed: <prefix>/<libdir>/cmake/abgs.
  get_filename_component(_abgs_libdir "${_abgs_here}/../.." ABSOLUTE)
  get_filename_component(_abgs_root "${_abgs_here}/../../.." ABSOLUTE)
  set(abgs_INCLUDE_DIR "${_abgs_root}/include")
  if(ABGS_LIBRARY_DIR)
    set(_abgs_libdirs "${ABGS_LIBRARY_DIR}")
  else()
    set(_abgs_libdirs "${_abgs_libdir}")
  endif()
  set(_abgs_hint "reinstall abgs (scripts/install.sh ${_abgs_root})")
  unset(_abgs_libdir)
endif()

# The first directory holding libabgs.so provides both libraries.
set(abgs_LIBRARY "")
set(abgs_STATIC_LIBRARY "")
set(_abgs_ok TRUE)
foreach(_abgs_dir IN LISTS _abgs_libdirs)
  if(EXISTS "${_abgs_dir}/libabgs.so")
    set(abgs_LIBRARY "${_abgs_dir}/libabgs.so")
    if(EXISTS "${_abgs_dir}/libabgs.a")
      set(abgs_STATIC_LIBRARY "${_abgs_dir}/libabgs.a")
    endif()
    break()
  endif()
endforeach()

if(NOT EXISTS "${abgs_INCLUDE_DIR}/abgs.h")
  set(_abgs_ok FALSE)
  set(abgs_NOT_FOUND_MESSAGE "abgs: header ${abgs_INCLUDE_DIR}/abgs.h not found; ${_abgs_hint}.")
elseif(NOT abgs_LIBRARY)
  string(REPLACE ";" ", " _abgs_where "${_abgs_libdirs}")
  set(_abgs_ok FALSE)
  set(abgs_NOT_FOUND_MESSAGE
      "abgs: libabgs.so is not built (looked in ${_abgs_where}); ${_abgs_hint}, or set ABGS_LIBRARY_DIR.")
  unset(_abgs_where)
endif()

if(NOT _abgs_ok)
  set(abgs_FOUND FALSE)
else()
  set(abgs_FOUND TRUE)

  if(NOT TARGET abgs::abgs)
    add_library(abgs::abgs SHARED IMPORTED)
    # cargo's cdylib has no SONAME: IMPORTED_NO_SONAME makes CMake link it with
    # -L<dir> -labgs, so executables record `libabgs.so` and not its full path.
    # Its own dependencies (libc, libm, libgcc_s) are recorded in the .so itself.
    set_target_properties(abgs::abgs PROPERTIES
      IMPORTED_LOCATION "${abgs_LIBRARY}"
      IMPORTED_NO_SONAME TRUE
      INTERFACE_INCLUDE_DIRECTORIES "${abgs_INCLUDE_DIR}")
  endif()

  if(abgs_STATIC_LIBRARY AND NOT TARGET abgs::abgs_static)
    # A Rust staticlib carries the standard library: the system libraries it
    # needs must be linked by the user.
    # FindThreads needs C or C++ enabled; plain -lpthread otherwise.
    set(_abgs_system_libs pthread dl m)
    if(CMAKE_C_COMPILER_LOADED OR CMAKE_CXX_COMPILER_LOADED)
      find_package(Threads QUIET)
      if(TARGET Threads::Threads)
        set(_abgs_system_libs Threads::Threads dl m)
      endif()
    endif()
    add_library(abgs::abgs_static STATIC IMPORTED)
    set_target_properties(abgs::abgs_static PROPERTIES
      IMPORTED_LOCATION "${abgs_STATIC_LIBRARY}"
      IMPORTED_LINK_INTERFACE_LANGUAGES "C"
      INTERFACE_INCLUDE_DIRECTORIES "${abgs_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES "${_abgs_system_libs}")
    unset(_abgs_system_libs)
  endif()
endif()

unset(_abgs_here)
unset(_abgs_root)
unset(_abgs_libdirs)
unset(_abgs_dir)
unset(_abgs_hint)
unset(_abgs_ok)
cmake_policy(POP)
