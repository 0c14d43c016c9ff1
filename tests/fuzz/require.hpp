// The fuzz targets' one way to report a finding: abort, which libFuzzer
// records as a crash with the input that caused it.
#pragma once

#include <cstdlib>
#include <string>

namespace bireg_fuzz {

inline void require(bool condition) {
  if (!condition) std::abort();
}

// A refusal's or a failure status's message: present, bounded.
inline void require_message(const std::string& message) {
  require(!message.empty());
  require(message.size() < 2000);
}

}  // namespace bireg_fuzz
