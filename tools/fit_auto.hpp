// bireg_fit --group auto: which pose-motion model the data need
// (bireg/statistics/model_selection.hpp), and that model's fit.
//
// The input is read as SE(3) poses (TUM, EuRoC, KITTI or the 4x4 matrix
// format). The five candidates (static, rotation only, translation only,
// rotation and straight line, screw) are fitted with the library's default
// options; the JSON holds the comparison table ("model_selection": one
// object per candidate with its parameters, residual RMS in rotation
// (degrees) and translation (data units), criterion, cross-validated error
// and verdict), the recommended model, whether another of the same
// complexity is indistinguishable ("ambiguous"), and the recommended
// model's predicted poses at the first and last timestamps ("g0", "g1").
// --output-trajectory writes the prediction at every input timestamp.
// Compiled as its own translation unit: the five candidates instantiate
// the SE(3), SO(3) and R^3 fits and means, and the tool then builds in
// parallel.
#pragma once

#include <optional>
#include <string>

#include "bireg/io/formats.hpp"
#include "cli_common.hpp"

namespace bireg_cli {

struct AutoCommand {
  InputOptions input;
  std::string output_trajectory;                   // empty: none
  std::optional<bireg::io::Format> output_format;  // empty: the input's
};

// Exit codes as bireg_fit's: 0 a model recommended, 2 invalid input, 3 no
// candidate could be fitted, 4 an output could not be written.
int run_auto(const AutoCommand& command);

}  // namespace bireg_cli
