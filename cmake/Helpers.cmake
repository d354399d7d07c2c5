include_guard(GLOBAL)

# Warnings and sanitizers for our own targets only (never global flags).
add_library(nsg_build_flags INTERFACE)
target_compile_options(nsg_build_flags INTERFACE -Wall -Wextra)
if(NSG_WERROR)
  target_compile_options(nsg_build_flags INTERFACE -Werror)
endif()
# Sanitizers: cmake/Sanitize.cmake (NSG_SANITIZE, NSG_BUILD_FUZZ).

# Precompiled headers. The third-party headers most files include are slow to parse: a file
# holding only the include, -fsyntax-only, GCC 12 on the 2-core machine (loaded): CLI11 5.6 s,
# nlohmann/json 4.1 s, gtest 3.5 s, Eigen 3.3 s, <filesystem> 1.5 s. Precompiled once per
# library, for the nsgraph binary and the Python module, and once for all test binaries
# (nsg_test_pch in tests/CMakeLists.txt), they cut the compile CPU time of 12 sampled files by
# 13 % (112.6 s against 129.2 s, each the faster of two runs).
# -DNSG_PCH=OFF compiles every file on its own (e.g. to check that each includes what it uses).
option(NSG_PCH "Precompile the heavy third-party headers" ON)
set(NSG_PCH_HEADERS <algorithm> <filesystem> <functional> <map> <memory> <optional> <set> <string>
    <string_view> <unordered_map> <vector> <nlohmann/json.hpp>)
# nsg_precompile(<target> [<header> ...]): NSG_PCH_HEADERS and the extra headers, for the
# target's own files.
function(nsg_precompile target)
  if(NSG_PCH)
    target_precompile_headers(${target} PRIVATE ${NSG_PCH_HEADERS} ${ARGN})
  endif()
endfunction()

# nsg_add_library(<module> SOURCES ... DEPS ... [PCH <header> ...] [NO_PCH]): lib/<module> ->
# target nsg_<module>, alias nsg::<module>, public headers under lib/<module>/include/nsg/<module>/;
# PCH names headers to precompile beyond NSG_PCH_HEADERS. A file compiled with options of its own
# (-ffp-contract=off for bit-exact arithmetic) sets SKIP_PRECOMPILE_HEADERS: a header parsed
# under other options must not reach it.
function(nsg_add_library module)
  cmake_parse_arguments(ARG "NO_PCH" "" "SOURCES;DEPS;PRIVATE_DEPS;PCH" ${ARGN})
  add_library(nsg_${module} STATIC ${ARG_SOURCES})
  add_library(nsg::${module} ALIAS nsg_${module})
  target_include_directories(nsg_${module}
    PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(nsg_${module} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS} nlohmann_json::nlohmann_json
    nsg_build_flags)
  if(NOT ARG_NO_PCH)
    nsg_precompile(nsg_${module} ${ARG_PCH})
  endif()
endfunction()

# The test binaries' shared precompiled header (made by nsg_test_pch; same flags as theirs).
function(nsg_use_test_pch target)
  if(NSG_PCH)
    target_link_libraries(${target} PRIVATE Eigen3::Eigen nlohmann_json::nlohmann_json)
    target_precompile_headers(${target} REUSE_FROM nsg_test_pch)
  endif()
endfunction()

# nsg_add_test(<module> [PART <part>] SOURCES ... DEPS ...): a GoogleTest binary
# test_<module>[_<part>]; CTest names are <module>/<Suite>.<Test> so `ctest -R graph/`
# runs one module whichever binary holds the test.
function(nsg_add_test module)
  cmake_parse_arguments(ARG "" "PART" "SOURCES;DEPS" ${ARGN})
  set(target test_${module})
  if(ARG_PART)
    set(target test_${module}_${ARG_PART})
  endif()
  add_executable(${target} ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} nsg_test_support GTest::gtest GTest::gtest_main nsg_build_flags)
  nsg_use_test_pch(${target})
  gtest_discover_tests(${target}
    TEST_PREFIX "${module}/"
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES ENVIRONMENT "NSG_SOURCE_DIR=${PROJECT_SOURCE_DIR};NSG_BINARY_DIR=${PROJECT_BINARY_DIR};NSG_EXE=$<TARGET_FILE:nsgraph>"
    DISCOVERY_TIMEOUT 60)
endfunction()
