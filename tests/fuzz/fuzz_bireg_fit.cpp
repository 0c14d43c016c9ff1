// libFuzzer target: bireg_fit, in-process (bireg_cli::fit_main), on any
// input file and a combination of its options.
//
// The first two bytes choose the options, the rest is the input file:
//   byte 0, bits 0-2: --group SO2, SO3, SE2, SE3, Sim3, SL3, GLp3, auto;
//           bits 3-5: the format (detected from the content, matrix, tum,
//                     euroc, kitti, kitti with the same text as --times);
//           bit 6: --project; bit 7: --output-trajectory FILE;
//   byte 1, bits 0-1: --loss none, huber, cauchy, tukey;
//           bit 2: --confidence 0.9; bit 3: --permutations 3 --seed 1;
//           bit 4: --output-band FILE; bit 5: --solver paper;
//           bit 6: --method series --order 16; bit 7: --threads 2 (else 1).
// --group auto gets the input options and --output-trajectory only (the
// rest is a usage error by design, which the tool test covers).
// Properties checked (abort = finding), whatever the input:
//   * the exit code is 0, 2, 3 or 5 (4 means the scratch files could not
//     be written, which is no property of the input);
//   * exit 2: nothing on stdout, exactly one line on stderr;
//   * otherwise: stdout is one JSON object with every number finite (no
//     nan or inf, and null only where --group auto documents an absent
//     value), exit 0 only with "status" "converged" or "rounding_floor"
//     (bireg::is_success) for an explicit group;
//   * every line on stderr names the tool, is printable and bounded;
//   * the files written (trajectory, band CSV) hold no nan or inf.
//
// Build and run (clang): see fuzz_fit.cpp, target fuzz_bireg_fit, corpus
// tests/fuzz/corpus_fuzz_bireg_fit.
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
  const std::string& directory = bireg_fuzz::scratch_directory();
  const std::string input = directory + "/input";
  const std::string trajectory = directory + "/trajectory";
  const std::string band = directory + "/band.csv";
  bireg_fuzz::write_file(input, std::string(reinterpret_cast<const char*>(data + 2), size - 2));

  static const char* const kGroups[] = {"SO2", "SO3", "SE2", "SE3", "Sim3", "SL3", "GLp3", "auto"};
  const std::string group = kGroups[a & 7];
  std::vector<std::string> args = {"bireg_fit", "--group", group};
  const std::vector<std::string> format = bireg_fuzz::format_options((a >> 3) & 7, input);
  args.insert(args.end(), format.begin(), format.end());
  if (a & 64) args.push_back("--project");
  if (a & 128) args.insert(args.end(), {"--output-trajectory", trajectory});
  if (group != "auto") {
    static const char* const kLosses[] = {nullptr, "huber", "cauchy", "tukey"};
    if (b & 3) args.insert(args.end(), {"--loss", kLosses[b & 3]});
    if (b & 4) args.insert(args.end(), {"--confidence", "0.9"});
    if (b & 8) args.insert(args.end(), {"--permutations", "3", "--seed", "1"});
    if (b & 16) args.insert(args.end(), {"--output-band", band});
    if (b & 32) args.insert(args.end(), {"--solver", "paper"});
    if (b & 64) args.insert(args.end(), {"--method", "series", "--order", "16"});
  }
  args.insert(args.end(), {"--threads", (b & 128) ? "2" : "1", input});

  const bireg_fuzz::ToolRun run = bireg_fuzz::run_tool(bireg_cli::fit_main, args);
  const std::string trajectory_text = bireg_fuzz::take_file(trajectory);
  const std::string band_text = bireg_fuzz::take_file(band);
  require(run.exit_code == 0 || run.exit_code == 2 || run.exit_code == 3 || run.exit_code == 5);
  bireg_fuzz::require_messages(run.err, "bireg_fit");
  if (run.exit_code == 2) {
    bireg_fuzz::require_refusal(run, "bireg_fit");
    return 0;
  }
  // --group auto: "recommended" and "recommended_group" are null when no
  // model is recommended, a candidate's "cv_error" when it was not
  // cross-validated (tools/fit_auto.cpp); no other value may be null.
  bireg_fuzz::require_json_object(run.out, {"recommended", "recommended_group", "cv_error"});
  if (run.exit_code == 0 && group != "auto") {
    require(run.out.find("\"status\": \"converged\"") != std::string::npos ||
            run.out.find("\"status\": \"rounding_floor\"") != std::string::npos);
  }
  bireg_fuzz::require_finite_text(trajectory_text);
  bireg_fuzz::require_finite_text(band_text);
  return 0;
}
