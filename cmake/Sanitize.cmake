# Sanitizer and fuzzing instrumentation for every target of the project (the libraries,
# nsgraph, tests, fuzzers), so a report points into our code whichever binary runs it.
#   -DNSG_SANITIZE=address,undefined   ASan + UBSan build; any UB report aborts the test.
#   -DNSG_BUILD_FUZZ=ON (clang)        libFuzzer coverage + ASan/UBSan for the fuzz/ targets.
# Third-party libraries come from Debian and stay uninstrumented.
include_guard(GLOBAL)

if(NSG_SANITIZE)
  string(REPLACE "," ";" _nsg_sanitizers "${NSG_SANITIZE}")
  foreach(s IN LISTS _nsg_sanitizers)
    if(NOT s MATCHES "^(address|undefined|leak|thread)$")
      message(FATAL_ERROR "NSG_SANITIZE: unknown sanitizer '${s}' (address, undefined, leak, thread)")
    endif()
  endforeach()
  if("address" IN_LIST _nsg_sanitizers AND "thread" IN_LIST _nsg_sanitizers)
    message(FATAL_ERROR "NSG_SANITIZE: address and thread cannot be combined")
  endif()
  add_compile_options(-fsanitize=${NSG_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${NSG_SANITIZE})
endif()

if(NSG_BUILD_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "NSG_BUILD_FUZZ needs clang: configure with CC=clang CXX=clang++")
  endif()
  # Coverage for libFuzzer in every object; only the fuzz_* executables link its main.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()
