// The generated bireg/version.hpp matches project(VERSION) of the top-level
// CMakeLists.txt (passed in by tests/CMakeLists.txt as BIREG_EXPECTED_*).
#include <cstdio>
#include <cstring>
#include <string>

#include "bireg/version.hpp"

static_assert(BIREG_VERSION_MAJOR == BIREG_EXPECTED_MAJOR, "BIREG_VERSION_MAJOR");
static_assert(BIREG_VERSION_MINOR == BIREG_EXPECTED_MINOR, "BIREG_VERSION_MINOR");
static_assert(BIREG_VERSION_PATCH == BIREG_EXPECTED_PATCH, "BIREG_VERSION_PATCH");
static_assert(BIREG_VERSION ==
                  BIREG_EXPECTED_MAJOR * 10000 + BIREG_EXPECTED_MINOR * 100 + BIREG_EXPECTED_PATCH,
              "BIREG_VERSION");

int main() {
  const std::string from_numbers = std::to_string(BIREG_VERSION_MAJOR) + "." +
                                   std::to_string(BIREG_VERSION_MINOR) + "." +
                                   std::to_string(BIREG_VERSION_PATCH);
  const bool string_ok = std::strcmp(bireg::version, BIREG_EXPECTED_VERSION) == 0;
  const bool numbers_ok = from_numbers == bireg::version;
  std::printf("bireg::version \"%s\", numbers %s, project version %s\n", bireg::version,
              from_numbers.c_str(), BIREG_EXPECTED_VERSION);
  return string_ok && numbers_ok ? 0 : 1;
}
