// The command-line tools as functions. Each tool's main() only calls its
// entry point, so that the fuzz targets (tests/fuzz/fuzz_bireg_fit.cpp,
// fuzz_bireg_smooth.cpp) run exactly the code a user runs, in-process.
//
// An entry point takes argc/argv as main() does, writes to the stdio
// streams stdout and stderr as they are when it is called, never calls
// exit(), keeps no state between calls, and returns the tool's exit code.
#pragma once

namespace bireg_cli {

// bireg_fit (tools/bireg_fit.cpp documents the options and exit codes).
int fit_main(int argc, char** argv);

// bireg_smooth (tools/bireg_smooth.cpp documents the options and exit codes).
int smooth_main(int argc, char** argv);

// bireg_compare (tools/bireg_compare.cpp documents the options and exit codes).
int compare_main(int argc, char** argv);

}  // namespace bireg_cli
