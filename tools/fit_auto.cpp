// bireg_fit --group auto (see fit_auto.hpp).
#include "fit_auto.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/io/writers.hpp"
#include "bireg/statistics/selection/model_selection.hpp"

namespace bireg_cli {

namespace {

// The group whose fit each model is (static: the bi-invariant mean); on
// Sim(3) data the rigid models carry a constant scale.
std::string group_of(bireg::MotionModel model, bireg::PoseGroup poses) {
  const bool similarities = poses == bireg::PoseGroup::sim3;
  const char* scale = similarities ? " + constant scale" : "";
  switch (model) {
    case bireg::MotionModel::static_pose:
      return similarities ? "Sim3 mean" : "SE3 mean";
    case bireg::MotionModel::rotation_only:
      return std::string("SO3") + scale;
    case bireg::MotionModel::translation_only:
      return std::string("R3") + scale;
    case bireg::MotionModel::rotation_and_line:
      return std::string("SO3 x R3") + scale;
    case bireg::MotionModel::screw:
      return std::string("SE3") + scale;
    case bireg::MotionModel::similarity:
      return "Sim3";
  }
  return "unknown";
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string candidate_json(const bireg::CandidateReport& c, bireg::PoseGroup poses) {
  using bireg::io::json_number;
  const char* verdict = c.recommended     ? "recommended"
                        : !c.fitted       ? "excluded"
                        : c.within_margin ? "within margin"
                                          : "rejected";
  const std::string log_scale = poses == bireg::PoseGroup::sim3
                                    ? ", \"log_scale_rms\": " + json_number(c.log_scale_rms)
                                    : std::string();
  return std::string("{\"model\": \"") + bireg::to_string(c.model) + "\", \"group\": \"" +
         group_of(c.model, poses) + "\", \"parameters\": " + std::to_string(c.parameters) +
         ", \"fitted\": " + (c.fitted ? "true" : "false") +
         ", \"rotation_rms_deg\": " + json_number(c.rotation_rms_degrees) +
         ", \"translation_rms\": " + json_number(c.translation_rms) + log_scale +
         ", \"criterion\": " + json_number(c.criterion) +
         ", \"cv_error\": " + (c.cv_error ? json_number(*c.cv_error) : std::string("null")) +
         ", \"verdict\": \"" + verdict + "\"" +
         (c.note.empty() ? std::string() : ", \"note\": " + json_string(c.note)) + "}";
}

// Whether every pose is rigid: SE(3)'s element test at the reader's tolerance,
// so that SE(3) data read as similarities are the SE(3) reader's data.
bool all_rigid(const std::vector<Eigen::Matrix4d>& poses) {
  const double tolerance = bireg::io::ReadOptions().element_tolerance;
  return std::all_of(poses.begin(), poses.end(), [tolerance](const Eigen::Matrix4d& g) {
    return bireg::SE3d::is_element(g, tolerance);
  });
}

}  // namespace

int run_auto(const AutoCommand& command) {
  namespace io = bireg::io;
  // One pass reads either group: Sim(3) reads the pose formats as scale 1,
  // and the data are SE(3) if every pose is rigid. --project applies to
  // rotations, so it reads SE(3).
  io::Trajectory<bireg::Sim3d> trajectory;
  std::optional<std::string> error;
  if (command.input.project) {
    io::Trajectory<bireg::SE3d> rigid;
    error = read_input<bireg::SE3d>(command.input, rigid);
    trajectory = io::rebind_trajectory<bireg::Sim3d>(std::move(rigid));
  } else {
    error = read_input<bireg::Sim3d>(command.input, trajectory);
  }
  if (error) {
    std::fprintf(stderr, "bireg_fit: %s\n", error->c_str());
    return kExitInvalid;
  }
  if (trajectory.observations.size() < 2) {
    std::fprintf(stderr, "bireg_fit: %s: need at least 2 poses, got %zu\n",
                 display_name(command.input.path).c_str(), trajectory.observations.size());
    return kExitInvalid;
  }
  const bireg::PoseGroup group =
      all_rigid(trajectory.observations) ? bireg::PoseGroup::se3 : bireg::PoseGroup::sim3;
  const bool similarities = group == bireg::PoseGroup::sim3;
  const io::Format format = command.output_format.value_or(trajectory.format);
  if (similarities && !command.output_trajectory.empty()) {
    if (auto problem =
            output_format_problem<bireg::Sim3d>(command.output_format, trajectory.format)) {
      std::fprintf(stderr, "bireg_fit: %s: %s\n", display_name(command.input.path).c_str(),
                   problem->c_str());
      return kExitInvalid;
    }
  }
  bireg::ModelSelectionOptions options;
  options.group = group;
  options.threads = command.threads;
  const bireg::ModelSelection selection =
      bireg::select_motion_model(trajectory.observations, trajectory.covariates, options);
  const std::optional<bireg::MotionPrediction>& prediction = selection.prediction;

  if (prediction && !command.output_trajectory.empty()) {
    std::vector<Eigen::Matrix4d> fitted;
    fitted.reserve(trajectory.covariates.size());
    for (double t : trajectory.covariates)
      fitted.push_back((*prediction)(t));
    const auto written =
        similarities ? write_output<bireg::Sim3d>(command.output_trajectory, format,
                                                  trajectory.format, trajectory.timestamps, fitted)
                     : write_output<bireg::SE3d>(command.output_trajectory, format,
                                                 trajectory.format, trajectory.timestamps, fitted);
    if (written) {
      std::fprintf(stderr, "bireg_fit: %s\n", written->c_str());
      return kExitWriteError;
    }
  }

  double t_min = trajectory.covariates.front(), t_max = t_min;
  for (double t : trajectory.covariates) {
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  std::string table;
  for (const bireg::CandidateReport& c : selection.candidates)
    table += (table.empty() ? "\n  " : ",\n  ") + candidate_json(c, group);
  const std::string projection =
      projection_json(command.input.project, trajectory.projection_correction);
  std::printf(
      "{\"group\": \"auto\", \"format\": \"%s\", \"pose_group\": \"%s\", \"n\": %zu%s,\n "
      "\"recommended\": %s, ",
      io::to_string(trajectory.format), similarities ? "Sim3" : "SE3",
      trajectory.observations.size(), projection.c_str(),
      selection.recommended ? json_string(bireg::to_string(*selection.recommended)).c_str()
                            : "null");
  std::printf(
      "\"recommended_group\": %s, \"ambiguous\": %s,\n \"message\": %s,\n",
      selection.recommended ? json_string(group_of(*selection.recommended, group)).c_str() : "null",
      selection.ambiguous ? "true" : "false", json_string(selection.message).c_str());
  if (prediction) {
    std::printf(" \"g0\": %s,\n \"g1\": %s,\n", io::json_matrix((*prediction)(t_min)).c_str(),
                io::json_matrix((*prediction)(t_max)).c_str());
  }
  std::printf(" \"t_min\": %s, \"t_max\": %s,\n \"model_selection\": [%s]}\n",
              io::render_timestamp(trajectory.origin, io::TimeUnit::seconds).c_str(),
              io::render_timestamp(trajectory.last, io::TimeUnit::seconds).c_str(), table.c_str());
  if (!stdout_written("bireg_fit")) return kExitWriteError;
  return prediction ? 0 : kExitNotConverged;
}

}  // namespace bireg_cli
