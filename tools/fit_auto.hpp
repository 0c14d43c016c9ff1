// bireg_fit --group auto: which pose-motion model the data need
// (bireg/statistics/selection/model_selection.hpp), and that model's fit.
//
// The input is read in one pass as Sim(3) (TUM, EuRoC, KITTI or the 4x4
// matrix format; the pose formats give similarities of scale 1). If every
// pose passes SE(3)'s element test at the reader's tolerance the data are
// SE(3) and the five rigid candidates are compared (static, rotation only,
// translation only, rotation and straight line, screw); otherwise they are
// similarities (a monocular reconstruction whose scale drifts) and the six
// Sim(3) candidates are (the five with a constant scale, and the Sim(3)
// geodesic), with residuals in Sim(3). --project re-orthonormalises
// rotations and so reads SE(3). The JSON holds "pose_group" (SE3 or Sim3),
// the comparison table ("model_selection": one object per candidate with
// its parameters, residual RMS in rotation (degrees), translation (data
// units) and, for Sim3, log-scale, criterion, cross-validated error and
// verdict), the recommended model, whether another of the same complexity
// is indistinguishable ("ambiguous"), and the recommended model's predicted
// poses at the first and last timestamps ("g0", "g1"). --output-trajectory
// writes the prediction at every input timestamp (similarities in the
// matrix format only).
// Compiled as its own translation unit: the candidates instantiate the
// SE(3), Sim(3), SO(3) and R^3 fits and means, and the tool then builds in
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
  int threads = 1;                                 // the candidates' and folds' fits
};

// Exit codes as bireg_fit's: 0 a model recommended, 2 invalid input, 3 no
// candidate could be fitted, 4 an output could not be written.
int run_auto(const AutoCommand& command);

}  // namespace bireg_cli
