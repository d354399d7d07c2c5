#pragma once
// Shared by the libFuzzer targets: the input bytes as a file (the readers take a path), and
// the one rule every target checks — bad bytes may only raise the input errors of
// nsg/core/error.h (exit 2). Anything else (another exception, InternalError, a sanitizer
// report, a crash) escapes and libFuzzer records it as a finding.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "nsg/core/error.h"

namespace nsg::fuzz {

// An in-memory file (memfd) holding exactly the given bytes, reachable by path
// (/proc/self/fd/N); one per process, rewritten for each input.
std::filesystem::path input_file(const uint8_t* data, size_t size);

// Runs `body`; swallows the expected input errors only.
template <class Body>
void expect_only_input_errors(Body&& body) {
  try {
    body();
  } catch (const InternalError&) {
    throw;  // an internal error on any input is a bug
  } catch (const ParseError&) {
  } catch (const DataError&) {
  } catch (const IoError&) {
  } catch (const ConfigError&) {
  }
}

}  // namespace nsg::fuzz
