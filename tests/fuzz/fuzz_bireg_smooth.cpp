// libFuzzer target: bireg_smooth, in-process (bireg_cli::smooth_main), on
// any input file, query file and a combination of its options.
//
// The first two bytes choose the options; the rest is the input file, up
// to its first NUL byte, and after it the --at file:
//   byte 0, bits 0-1: --group SO2, SO3, SE2, SE3;
//           bits 2-4: the format (detected from the content, matrix, tum,
//                     euroc, kitti, kitti with the same text as --times);
//           bit 5: --project; bit 6: --velocity FILE;
//           bit 7: --at FILE (the text after the NUL byte);
//   byte 1, bits 0-3: --bandwidth 2^(k - 8) s for k = 1..15, auto for 0;
//           bits 4-5: --kernel gaussian, epanechnikov, tricube, gaussian;
//           bit 6: --output-format matrix; bit 7: --threads 2 (else 1).
// Properties checked (abort = finding), whatever the input:
//   * the exit code is 0, 2 or 3;
//   * exit 2: nothing on stdout, exactly one line on stderr;
//   * every line on stderr names the tool, is printable and bounded;
//   * otherwise the smoothed trajectory and the velocity CSV's numbers
//     hold no nan or inf, and the CSV has a header and one line per query,
//     each ending in its status, at least as many as output poses (a
//     failed query's pose is left out; a matrix-format pose is one line,
//     the other formats' too), and on exit 0 all "ok", one per pose.
//
// Build and run (clang): see fuzz_fit.cpp, target fuzz_bireg_smooth,
// corpus tests/fuzz/corpus_fuzz_bireg_smooth.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "entry_points.hpp"
#include "tool_capture.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using bireg_fuzz::require;
  if (size < 2) return 0;
  const std::uint8_t a = data[0];
  const std::uint8_t b = data[1];
  const std::string text(reinterpret_cast<const char*>(data + 2), size - 2);
  const std::size_t split = text.find('\0');
  const std::string& directory = bireg_fuzz::scratch_directory();
  const std::string input = directory + "/input";
  const std::string at = directory + "/at";
  const std::string output = directory + "/smoothed";
  const std::string velocity = directory + "/velocity.csv";
  bireg_fuzz::write_file(input, text.substr(0, split));
  bireg_fuzz::write_file(at, split == std::string::npos ? std::string() : text.substr(split + 1));

  static const char* const kGroups[] = {"SO2", "SO3", "SE2", "SE3"};
  std::vector<std::string> args = {"bireg_smooth", "--group", kGroups[a & 3]};
  const std::vector<std::string> format = bireg_fuzz::format_options((a >> 2) & 7, input);
  args.insert(args.end(), format.begin(), format.end());
  if (a & 32) args.push_back("--project");
  if (a & 64) args.insert(args.end(), {"--velocity", velocity});
  if (a & 128) args.insert(args.end(), {"--at", at});
  const int bandwidth_exponent = b & 15;
  args.insert(args.end(),
              {"--bandwidth", bandwidth_exponent == 0
                                  ? std::string("auto")
                                  : std::to_string(std::ldexp(1.0, bandwidth_exponent - 8))});
  static const char* const kKernels[] = {"gaussian", "epanechnikov", "tricube", "gaussian"};
  args.insert(args.end(), {"--kernel", kKernels[(b >> 4) & 3]});
  if (b & 64) args.insert(args.end(), {"--output-format", "matrix"});
  args.insert(args.end(), {"--output", output, "--threads", (b & 128) ? "2" : "1", input});

  const bireg_fuzz::ToolRun run = bireg_fuzz::run_tool(bireg_cli::smooth_main, args);
  const std::string smoothed = bireg_fuzz::take_file(output);
  const std::string velocity_text = bireg_fuzz::take_file(velocity);
  require(run.exit_code == 0 || run.exit_code == 2 || run.exit_code == 3);
  bireg_fuzz::require_messages(run.err, "bireg_smooth");
  if (run.exit_code == 2) {
    bireg_fuzz::require_refusal(run, "bireg_smooth");
    return 0;
  }
  require(run.out.empty());  // the poses went to --output
  bireg_fuzz::require_finite_text(smoothed);
  if (a & 64) {
    require(velocity_text.compare(0, 2, "t,") == 0);
    std::size_t poses = 0;
    for (std::size_t start = 0; start < smoothed.size();) {
      const std::size_t end = smoothed.find('\n', start);
      poses += smoothed[start] != '#';
      start = end == std::string::npos ? smoothed.size() : end + 1;
    }
    // Per row: the numbers before the status column, and the status.
    std::size_t rows = 0, ok_rows = 0;
    std::string numbers;
    for (std::size_t start = velocity_text.find('\n') + 1; start < velocity_text.size();) {
      const std::size_t end = velocity_text.find('\n', start);
      require(end != std::string::npos);
      const std::string row = velocity_text.substr(start, end - start);
      const std::size_t failed = row.find(",failed: ") != std::string::npos
                                     ? row.find(",failed: ")
                                     : row.find(",\"failed: ");
      const bool ok = row.size() >= 3 && row.compare(row.size() - 3, 3, ",ok") == 0;
      require(ok || failed != std::string::npos);
      numbers += row.substr(0, ok ? row.size() - 3 : failed) + '\n';
      ++rows;
      ok_rows += ok ? 1 : 0;
      start = end + 1;
    }
    bireg_fuzz::require_finite_text(numbers);
    // The velocity may come from its own bandwidth's pass: a row can fail
    // there and keep its pose, or fail for its pose and keep its velocity.
    require(ok_rows <= rows && poses <= rows);
    require(run.exit_code != 0 || (ok_rows == rows && poses == rows));
  }
  return 0;
}
