// bireg_fit --group auto (see fit_auto.hpp).
#include "fit_auto.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/io/writers.hpp"
#include "bireg/statistics/model_selection.hpp"

namespace bireg_cli {

namespace {

// The group whose fit each model is (static: the bi-invariant mean).
const char* group_of(bireg::MotionModel model) {
  switch (model) {
    case bireg::MotionModel::static_pose:
      return "SE3 mean";
    case bireg::MotionModel::rotation_only:
      return "SO3";
    case bireg::MotionModel::translation_only:
      return "R3";
    case bireg::MotionModel::rotation_and_line:
      return "SO3 x R3";
    case bireg::MotionModel::screw:
      return "SE3";
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

std::string candidate_json(const bireg::CandidateReport& c) {
  using bireg::io::json_number;
  const char* verdict = c.recommended     ? "recommended"
                        : !c.fitted       ? "excluded"
                        : c.within_margin ? "within margin"
                                          : "rejected";
  return std::string("{\"model\": \"") + bireg::to_string(c.model) + "\", \"group\": \"" +
         group_of(c.model) + "\", \"parameters\": " + std::to_string(c.parameters) +
         ", \"fitted\": " + (c.fitted ? "true" : "false") +
         ", \"rotation_rms_deg\": " + json_number(c.rotation_rms_degrees) +
         ", \"translation_rms\": " + json_number(c.translation_rms) +
         ", \"criterion\": " + json_number(c.criterion) +
         ", \"cv_error\": " + (c.cv_error ? json_number(*c.cv_error) : std::string("null")) +
         ", \"verdict\": \"" + verdict + "\"" +
         (c.note.empty() ? std::string() : ", \"note\": " + json_string(c.note)) + "}";
}

}  // namespace

int run_auto(const AutoCommand& command) {
  namespace io = bireg::io;
  using G = bireg::SE3d;
  io::Trajectory<G> trajectory;
  if (auto error = read_input<G>(command.input, trajectory)) {
    std::fprintf(stderr, "bireg_fit: %s\n", error->c_str());
    return kExitInvalid;
  }
  if (trajectory.observations.size() < 2) {
    std::fprintf(stderr, "bireg_fit: %s: need at least 2 poses, got %zu\n",
                 display_name(command.input.path).c_str(), trajectory.observations.size());
    return kExitInvalid;
  }
  const bireg::ModelSelection selection =
      bireg::select_motion_model(trajectory.observations, trajectory.covariates);
  std::optional<bireg::MotionPrediction> prediction;
  if (selection.recommended) {
    prediction = bireg::fit_motion_model(*selection.recommended, trajectory.observations,
                                         trajectory.covariates);
  }

  if (prediction && !command.output_trajectory.empty()) {
    std::vector<G::Element> fitted;
    fitted.reserve(trajectory.covariates.size());
    for (double t : trajectory.covariates)
      fitted.push_back((*prediction)(t));
    const io::Format format = command.output_format.value_or(trajectory.format);
    if (auto error = write_output<G>(command.output_trajectory, format, trajectory.format,
                                     trajectory.timestamps, fitted)) {
      std::fprintf(stderr, "bireg_fit: %s\n", error->c_str());
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
    table += (table.empty() ? "\n  " : ",\n  ") + candidate_json(c);
  std::printf("{\"group\": \"auto\", \"format\": \"%s\", \"n\": %zu,\n \"recommended\": %s, ",
              io::to_string(trajectory.format), trajectory.observations.size(),
              selection.recommended ? json_string(bireg::to_string(*selection.recommended)).c_str()
                                    : "null");
  std::printf(
      "\"recommended_group\": %s, \"ambiguous\": %s,\n \"message\": %s,\n",
      selection.recommended ? json_string(group_of(*selection.recommended)).c_str() : "null",
      selection.ambiguous ? "true" : "false", json_string(selection.message).c_str());
  if (prediction) {
    std::printf(" \"g0\": %s,\n \"g1\": %s,\n", io::json_matrix((*prediction)(t_min)).c_str(),
                io::json_matrix((*prediction)(t_max)).c_str());
  }
  std::printf(" \"t_min\": %s, \"t_max\": %s,\n \"model_selection\": [%s]}\n",
              io::render_timestamp(trajectory.origin, io::TimeUnit::seconds).c_str(),
              io::render_timestamp(trajectory.last, io::TimeUnit::seconds).c_str(), table.c_str());
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "bireg_fit: <stdout>: write error: %s\n",
                 errno != 0 ? std::strerror(errno) : "unknown");
    return kExitWriteError;
  }
  return prediction ? 0 : kExitNotConverged;
}

}  // namespace bireg_cli
