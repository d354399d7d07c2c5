include_guard(GLOBAL)

# Warnings and sanitizers for our own targets only (never global flags).
add_library(nsg_build_flags INTERFACE)
target_compile_options(nsg_build_flags INTERFACE -Wall -Wextra)
if(NSG_WERROR)
  target_compile_options(nsg_build_flags INTERFACE -Werror)
endif()
# Sanitizers: cmake/Sanitize.cmake (NSG_SANITIZE, NSG_BUILD_FUZZ).

# nsg_add_library(<module> SOURCES ... DEPS ...): lib/<module> -> target nsg_<module>,
# alias nsg::<module>, public headers under lib/<module>/include/nsg/<module>/.
function(nsg_add_library module)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(nsg_${module} STATIC ${ARG_SOURCES})
  add_library(nsg::${module} ALIAS nsg_${module})
  target_include_directories(nsg_${module}
    PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(nsg_${module} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS} nsg_build_flags)
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
  gtest_discover_tests(${target}
    TEST_PREFIX "${module}/"
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES ENVIRONMENT "NSG_SOURCE_DIR=${PROJECT_SOURCE_DIR};NSG_BINARY_DIR=${PROJECT_BINARY_DIR};NSG_EXE=$<TARGET_FILE:nsgraph>"
    DISCOVERY_TIMEOUT 60)
endfunction()
