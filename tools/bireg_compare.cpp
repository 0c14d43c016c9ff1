// bireg_compare: do two cohorts differ? A bi-invariant two-sample test of
// their subjects' trends, or of their group elements.
//
//   bireg_compare --group SO2|SO3|SE2|SE3|GLp3 [--elements] [--population]
//                 [--statistic hotelling|bhattacharyya|hellinger]
//                 [--variant invariant|published] [--permutations B] [--seed S]
//                 [--format matrix|tum|euroc|kitti] [--project] [--threads N] MANIFEST
//   bireg_compare --help | --version
//
// MANIFEST is a CSV file whose header names the columns `path` and `cohort`
// (and optionally `subject`; other columns are ignored); each further line
// is one file, and the `cohort` column must hold exactly two names (the
// first named is cohort A). Relative paths are resolved against the
// manifest's folder. Fields may be double-quoted (a quote inside doubled).
//
// Trends (the default; `--trend` says so explicitly): each path is one
// subject's trajectory in any format bireg_fit reads (--format, --project
// as there), its times on the study's clock (all subjects' timestamps are
// read as one time axis, e.g. days since a common baseline; "interval" in
// the JSON is in seconds after the earliest of them). Every subject gets
// its geodesic fit (fit_many), all on one covariate interval, the earliest
// to the latest time of all subjects: a trend's endpoints are only
// comparable on a shared interval. The two
// cohorts' trends (gamma(t0), gamma(t1)) are compared as elements of
// G x G (compare_trends; docs/cohorts.md, "Trends"). A subject whose fit
// fails is listed with its status and left out of the test (exit code 3).
// --population adds the population trend of all subjects and of each
// cohort (population_trend: the mean trend, the population's velocity
// with its standard errors, and the subjects flagged as outlying).
//
// Elements (--elements): each path holds group elements, one per line as
// the matrix's entries in row-major order, comma- or space-separated, no
// covariate; blank lines and lines starting with '#' are skipped. All the
// elements of a cohort's files form that cohort's sample
// (two_sample_test).
//
// The statistic (default hotelling), variant (default invariant: the
// second sample carried to the first's mean by parallel transport, which
// makes the statistic invariant under inversion too; published: the
// literature's), permutations (default 9999) and seed (default 0) are
// those of bireg::TwoSampleOptions (docs/cohorts.md); the p-value is
// (1 + #{T_b >= T}) / (B + 1). --threads N (default: every core) runs the
// relabellings and the subjects' fits; the output does not depend on N.
//
// Prints one JSON object on stdout: "statistic", "variant", "value" (T^2,
// D_B or H^2), "p_value", "permutations", "seed", "compared" ("trends" or
// "elements"), "cohorts" (per cohort: "name", "size", and "mean": a matrix,
// or for trends {"start", "end"} matrices on the shared "interval"),
// "subjects" for trends (per manifest line: "path", "cohort", "subject",
// "status", "message"), and "population" with --population.
//
// Exit codes: 0 the test ran; 2 invalid input or usage (one line on stderr
// naming the file and line: the manifest's, or a subject's file's); 3 the
// test ran but some subjects' fits failed (they are left out, and named in
// the JSON and on stderr), or it could not run because a mean or too many
// fits failed (one line on stderr says why); 4 the output could not be
// written.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/line_reader.hpp"
#include "bireg/io/numbers.hpp"
#include "bireg/io/writers.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/cohorts/trends.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/version.hpp"
#include "cli_common.hpp"
#include "entry_points.hpp"

namespace {

namespace io = bireg::io;
using bireg::io::json_matrix;
using bireg::io::json_number;
using bireg_cli::json_text;
using bireg_cli::kExitInvalid;
using bireg_cli::kExitNotConverged;
using bireg_cli::kExitWriteError;

constexpr const char* kUsage =
    "usage: bireg_compare --group SO2|SO3|SE2|SE3|GLp3 [--elements | --trend] [--population]\n"
    "                     [--statistic hotelling|bhattacharyya|hellinger]\n"
    "                     [--variant invariant|published] [--permutations B] [--seed S]\n"
    "                     [--format matrix|tum|euroc|kitti] [--project] [--threads N] MANIFEST\n"
    "       bireg_compare --help | --version\n";

constexpr const char* kHelp =
    "Compares two cohorts with a bi-invariant two-sample test and prints one JSON\n"
    "object on stdout (README.md, \"Comparing cohorts\"; docs/cohorts.md).\n"
    "\n"
    "MANIFEST: CSV with a header naming the columns path and cohort (optionally\n"
    "subject); one file per line, exactly two cohort names; relative paths are\n"
    "resolved against the manifest's folder.\n"
    "\n"
    "Options (each at most once):\n"
    "  --group G          SO2, SO3, SE2, SE3 or GLp3 (3x3 matrices of positive\n"
    "                     determinant, matrix format only)\n"
    "  --trend            each path is a subject's trajectory: one geodesic per subject\n"
    "                     on the subjects' shared time interval, the cohorts' trends\n"
    "                     compared in G x G (the default)\n"
    "  --elements         each path holds group elements, one per line (the matrix's\n"
    "                     entries, row-major, comma- or space-separated, no time)\n"
    "  --population       also the population trend of all subjects and of each cohort\n"
    "                     (trends only)\n"
    "  --statistic S      hotelling (default), bhattacharyya or hellinger\n"
    "  --variant V        invariant (default: also invariant under inversion) or\n"
    "                     published\n"
    "  --permutations B   random relabellings, 0 to 100000000 (default 9999; 0: the\n"
    "                     statistic only, p_value 1)\n"
    "  --seed S           of the relabellings (default 0)\n"
    "  --format F         the trajectories' format (default: detected per file)\n"
    "  --project          re-orthonormalise the trajectories' rotations\n"
    "  --threads N        threads, 1 to 1024 (default: every core); the output does not\n"
    "                     depend on N\n"
    "  --help, --version  this text; the version\n"
    "\n"
    "Exit codes: 0 the test ran; 2 invalid input or usage (one line naming\n"
    "file:line); 3 some subjects' fits failed (left out of the test, named in the\n"
    "JSON), or the test could not run (a mean or too many fits failed); 4 the output\n"
    "could not be written.\n";

struct Command {
  std::string group;
  bool elements = false;
  bool population = false;
  bireg::TwoSampleStatistic statistic = bireg::TwoSampleStatistic::hotelling;
  bireg::TwoSampleVariant variant = bireg::TwoSampleVariant::invariant;
  int permutations = 9999;
  std::uint64_t seed = 0;
  std::optional<io::Format> format;
  bool project = false;
  int threads = bireg_cli::default_threads();
  std::string manifest;
  bool help = false;
  bool version = false;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "bireg_compare: %s\n", message.c_str());
  return kExitInvalid;
}

// Parses argv into `command`; returns an error message or nothing.
std::optional<std::string> parse_command(int argc, char** argv, Command& command) {
  std::set<std::string> seen;
  bool trend = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-" || arg.empty() || arg[0] != '-') {
      if (!command.manifest.empty()) return "more than one manifest";
      command.manifest = arg;
      continue;
    }
    if (arg == "--help" || arg == "-h") {
      command.help = true;
      return std::nullopt;
    }
    if (arg == "--version") {
      command.version = true;
      return std::nullopt;
    }
    if (!seen.insert(arg).second) return "option " + arg + " given twice";
    if (arg == "--elements" || arg == "--trend" || arg == "--population" || arg == "--project") {
      command.elements = command.elements || arg == "--elements";
      trend = trend || arg == "--trend";
      command.population = command.population || arg == "--population";
      command.project = command.project || arg == "--project";
      continue;
    }
    if (i + 1 >= argc) return "option " + arg + " needs a value";
    const std::string v = argv[++i];
    if (arg == "--group") {
      command.group = v;
    } else if (arg == "--statistic") {
      bool known = false;
      for (const auto s :
           {bireg::TwoSampleStatistic::hotelling, bireg::TwoSampleStatistic::bhattacharyya,
            bireg::TwoSampleStatistic::hellinger}) {
        if (v == bireg::to_string(s)) {
          command.statistic = s;
          known = true;
        }
      }
      if (!known) return "unknown statistic '" + v + "' (hotelling, bhattacharyya or hellinger)";
    } else if (arg == "--variant") {
      if (v != "invariant" && v != "published") {
        return "unknown variant '" + v + "' (invariant or published)";
      }
      command.variant = v == "invariant" ? bireg::TwoSampleVariant::invariant
                                         : bireg::TwoSampleVariant::published;
    } else if (arg == "--permutations") {
      if (!bireg_cli::parse_count(v, command.permutations) ||
          command.permutations > bireg::kMaxTwoSamplePermutations) {
        return "--permutations needs an integer in [0, " +
               std::to_string(bireg::kMaxTwoSamplePermutations) + "], got '" + v + "'";
      }
    } else if (arg == "--seed") {
      double seed = 0;
      if (!bireg_cli::parse_number(v, seed) || seed < 0 || seed != std::floor(seed) ||
          seed > 9007199254740992.0) {
        return "--seed needs an integer in [0, 2^53], got '" + v + "'";
      }
      command.seed = static_cast<std::uint64_t>(seed);
    } else if (arg == "--format") {
      if (auto error = bireg_cli::parse_format(v, command.format)) return error;
    } else if (arg == "--threads") {
      if (auto error = bireg_cli::parse_threads(v, command.threads)) return error;
    } else {
      return "unknown option " + arg;
    }
  }
  if (command.elements && trend) return "--elements and --trend exclude each other";
  if (command.elements && command.population) return "--population goes with trends";
  if (command.elements && (command.format || command.project)) {
    return "--format and --project go with trajectories, not --elements";
  }
  if (command.group.empty()) return "--group is required";
  if (command.manifest.empty()) return "no manifest (use - for standard input)";
  return std::nullopt;
}

// One line of the manifest: a file and its cohort.
struct Entry {
  std::string path;      // as written
  std::string resolved;  // against the manifest's folder
  std::string subject;   // empty when the manifest has no subject column
  std::size_t cohort = 0;
  std::uint64_t line = 0;
};

struct Manifest {
  std::string name;                  // as messages show it
  std::vector<std::string> cohorts;  // in order of first appearance
  std::vector<Entry> entries;
};

// A CSV line's fields; double-quoted fields may hold commas and doubled
// quotes. False when a quote is not closed.
bool csv_fields(std::string_view line, std::vector<std::string>& fields) {
  fields.assign(1, std::string());
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  for (std::string& field : fields) {  // spaces around a field are not part of it
    const std::size_t first = field.find_first_not_of(" \t");
    const std::size_t last = field.find_last_not_of(" \t");
    field = first == std::string::npos ? std::string() : field.substr(first, last - first + 1);
  }
  return !quoted;
}

// Reads the manifest; returns the one-line message naming file:line.
std::optional<std::string> read_manifest(const std::string& path, Manifest& manifest) {
  using bireg_cli::where;
  manifest.name = bireg_cli::display_name(path);
  std::string problem;
  std::FILE* file = bireg_cli::open_input(path, problem);
  if (!file) return problem;
  const std::filesystem::path folder =
      path == "-" ? std::filesystem::path() : std::filesystem::path(path).parent_path();
  io::FileSource source(file);
  io::LineReader reader(source);
  std::string_view line;
  std::vector<std::string> fields;
  int path_column = -1, cohort_column = -1, subject_column = -1;
  std::size_t columns = 0;
  std::optional<std::string> error;
  while (!error && reader.next(line)) {
    const std::uint64_t number = reader.line_number();
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    if (!csv_fields(line, fields)) {
      error = where(manifest.name, number) + ": a quoted field is not closed";
      break;
    }
    if (path_column < 0) {  // the header
      for (std::size_t k = 0; k < fields.size(); ++k) {
        int* column = fields[k] == "path"      ? &path_column
                      : fields[k] == "cohort"  ? &cohort_column
                      : fields[k] == "subject" ? &subject_column
                                               : nullptr;
        if (!column) continue;
        if (*column >= 0) {
          error = where(manifest.name, number) + ": the header names '" + fields[k] + "' twice";
          break;
        }
        *column = static_cast<int>(k);
      }
      if (error) break;
      if (path_column < 0 || cohort_column < 0) {
        error = where(manifest.name, number) +
                ": the header must name the columns path and cohort (and optionally subject), "
                "got " +
                io::quote_excerpt(line);
        path_column = -1;
        break;
      }
      columns = fields.size();
      continue;
    }
    if (fields.size() != columns) {
      error = where(manifest.name, number) + ": expected " + std::to_string(columns) +
              " fields as in the header, found " + std::to_string(fields.size());
      break;
    }
    Entry entry;
    entry.line = number;
    entry.path = fields[static_cast<std::size_t>(path_column)];
    const std::string& cohort = fields[static_cast<std::size_t>(cohort_column)];
    if (subject_column >= 0) entry.subject = fields[static_cast<std::size_t>(subject_column)];
    if (entry.path.empty() || cohort.empty()) {
      error = where(manifest.name, number) + ": the path and the cohort must not be empty";
      break;
    }
    const std::filesystem::path file_path(entry.path);
    entry.resolved = file_path.is_absolute() ? entry.path : (folder / file_path).string();
    std::size_t index = 0;
    while (index < manifest.cohorts.size() && manifest.cohorts[index] != cohort)
      ++index;
    if (index == manifest.cohorts.size()) manifest.cohorts.push_back(cohort);
    entry.cohort = index;
    manifest.entries.push_back(std::move(entry));
  }
  if (!error && reader.error()) {
    error = where(manifest.name, reader.error()->line) + ": " + reader.error()->message;
  }
  if (file != stdin) std::fclose(file);
  if (error) return error;
  if (path_column < 0) return manifest.name + ": empty (a header naming path and cohort first)";
  if (manifest.cohorts.size() != 2) {
    std::string names;
    for (const std::string& c : manifest.cohorts)
      names += (names.empty() ? "" : ", ") + io::quote_excerpt(c);
    return manifest.name + ": exactly two cohorts are compared, found " +
           std::to_string(manifest.cohorts.size()) + (names.empty() ? "" : " (" + names + ")");
  }
  return std::nullopt;
}

// Where an element of a cohort's sample came from.
struct Origin {
  std::size_t entry;
  std::uint64_t line;
};

// Reads one --elements file into `sample`; returns the one-line message
// naming file:line.
template <class G>
std::optional<std::string> read_elements(const Entry& entry, std::size_t entry_index,
                                         std::vector<typename G::Element>& sample,
                                         std::vector<Origin>& origins) {
  using bireg_cli::where;
  constexpr int kSide = G::Element::RowsAtCompileTime;
  std::string problem;
  std::FILE* file = bireg_cli::open_input(entry.resolved, problem);
  if (!file) return problem;
  const std::string name = entry.resolved;
  io::FileSource source(file);
  io::LineReader reader(source);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::optional<std::string> error;
  const std::size_t before = sample.size();
  while (!error && reader.next(line)) {
    io::split_tokens(line, tokens);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    if (tokens.size() != std::size_t(kSide * kSide)) {
      error = where(name, reader.line_number()) + ": expected " + std::to_string(kSide * kSide) +
              " numbers (a " + std::to_string(kSide) + "x" + std::to_string(kSide) +
              " matrix, row-major), found " + std::to_string(tokens.size());
      break;
    }
    typename G::Element g;
    for (int k = 0; k < kSide * kSide && !error; ++k) {
      double value = 0;
      if (auto bad = io::parse_number(tokens[std::size_t(k)], value)) {
        error = where(name, reader.line_number()) + ": " + *bad;
      }
      g(k / kSide, k % kSide) = value;
    }
    if (error) break;
    sample.push_back(g);
    origins.push_back({entry_index, reader.line_number()});
  }
  if (!error && reader.error()) {
    error = where(name, reader.error()->line) + ": " + reader.error()->message;
  }
  if (file != stdin) std::fclose(file);
  if (!error && sample.size() == before) error = name + ": no elements";
  return error;
}

// A cohort's mean in the JSON: a matrix, or a trend's two matrices.
template <class Scalar, int Rows, int Cols, int Options, int MaxRows, int MaxCols>
std::string mean_json(
    const std::optional<Eigen::Matrix<Scalar, Rows, Cols, Options, MaxRows, MaxCols>>& mean) {
  return mean ? json_matrix(*mean) : std::string("null");
}

template <class Start, class End>
std::string mean_json(const std::optional<bireg::ProductElement<Start, End>>& mean) {
  if (!mean) return "null";
  return "{\"start\": " + json_matrix(mean->first) + ", \"end\": " + json_matrix(mean->second) +
         "}";
}

// The cohorts' part of the JSON: name, size, mean.
template <class Element>
std::string cohorts_json(const Manifest& manifest, const std::size_t sizes[2],
                         const std::optional<Element> means[2]) {
  std::string s = "[";
  for (std::size_t c = 0; c < 2; ++c) {
    s += std::string(c ? ", " : "") + "{\"name\": " + json_text(manifest.cohorts[c]) +
         ", \"size\": " + std::to_string(sizes[c]) + ", \"mean\": " + mean_json(means[c]) + "}";
  }
  return s + "]";
}

// The test's part of the JSON, up to the cohorts.
template <class Result>
std::string test_json(const Command& command, const Result& result, const char* compared) {
  return std::string("{\"statistic\": ") + json_text(bireg::to_string(command.statistic)) +
         ", \"variant\": " + json_text(bireg::to_string(command.variant)) +
         ", \"value\": " + json_number(result.value) +
         ", \"p_value\": " + json_number(result.p_value) +
         ", \"permutations\": " + std::to_string(result.permutations) +
         ", \"failed_permutations\": " + std::to_string(result.failed_permutations) +
         ", \"seed\": " + std::to_string(command.seed) + ", \"compared\": \"" + compared + "\"";
}

bireg::TwoSampleOptions<double> test_options(const Command& command) {
  bireg::TwoSampleOptions<double> options;
  options.statistic = command.statistic;
  options.variant = command.variant;
  options.permutations = command.permutations;
  options.seed = command.seed;
  options.threads = command.threads;
  return options;
}

int print(const std::string& json) {
  std::printf("%s\n", json.c_str());
  return bireg_cli::stdout_written("bireg_compare") ? 0 : kExitWriteError;
}

// Why a test that did not run failed, naming the element's file:line.
std::string test_failure(const Manifest& manifest, const std::string& message, char bad_sample,
                         std::ptrdiff_t bad_index, const std::vector<Origin> origins[2]) {
  if (bad_index < 0 || (bad_sample != 'A' && bad_sample != 'B')) {
    return manifest.name + ": " + message;
  }
  const std::vector<Origin>& from = origins[bad_sample == 'A' ? 0 : 1];
  if (std::size_t(bad_index) >= from.size()) return manifest.name + ": " + message;
  const Origin& o = from[std::size_t(bad_index)];
  return bireg_cli::where(manifest.entries[o.entry].resolved, o.line) + ": " + message;
}

template <class G>
int run_elements(const Command& command, const Manifest& manifest) {
  std::vector<typename G::Element> samples[2];
  std::vector<Origin> origins[2];
  for (std::size_t e = 0; e < manifest.entries.size(); ++e) {
    const Entry& entry = manifest.entries[e];
    if (auto error = read_elements<G>(entry, e, samples[entry.cohort], origins[entry.cohort])) {
      return fail(*error);
    }
  }
  const bireg::TwoSampleResult<G> result =
      bireg::two_sample_test<G>(samples[0], samples[1], test_options(command));
  if (!result.ok()) {
    const std::string why =
        test_failure(manifest, result.message, result.bad_sample, result.bad_index, origins);
    if (result.status == bireg::Status::invalid_input) return fail(why);
    std::fprintf(stderr, "bireg_compare: %s\n", why.c_str());
    return kExitNotConverged;
  }
  const std::size_t sizes[2] = {samples[0].size(), samples[1].size()};
  const std::optional<typename G::Element> means[2] = {result.mean_a, result.mean_b};
  return print(test_json(command, result, "elements") +
               ", \"cohorts\": " + cohorts_json(manifest, sizes, means) + "}");
}

// The population trend's JSON object.
template <class G>
std::string population_json(const bireg::PopulationTrend<G>& p,
                            const std::vector<std::size_t>& members,
                            const std::vector<Entry>& entries) {
  if (!p.ok()) {
    return "{\"subjects\": " + std::to_string(p.subjects) +
           ", \"status\": " + json_text(bireg::to_string(p.status)) +
           ", \"message\": " + json_text(p.message) + "}";
  }
  std::string errors = "[";
  for (int k = 0; k < G::dof; ++k) {
    using std::sqrt;
    errors += (k ? ", " : "") + json_number(sqrt(p.velocity_covariance(k, k)));
  }
  std::string outlying = "[";
  bool first = true;
  for (std::size_t i = 0; i < p.outlying.size(); ++i) {
    if (!p.outlying[i]) continue;
    outlying += std::string(first ? "" : ", ") + std::to_string(entries[members[i]].line);
    first = false;
  }
  std::string velocity = "[";
  for (int k = 0; k < G::dof; ++k)
    velocity += (k ? ", " : "") + json_number(p.velocity[k]);
  return "{\"subjects\": " + std::to_string(p.subjects) +
         ", \"status\": \"ok\", \"start\": " + json_matrix(p.mean->first) +
         ", \"end\": " + json_matrix(p.mean->second) + ", \"velocity\": " + velocity +
         "], \"velocity_standard_error\": " + errors +
         "], \"outlier_threshold\": " + json_number(p.outlier_threshold) +
         ", \"outlying_manifest_lines\": " + outlying + "]}";
}

template <class G>
int run_trends(const Command& command, const Manifest& manifest) {
  using Trend = bireg::Trend<G>;
  std::vector<io::Trajectory<G>> trajectories(manifest.entries.size());
  for (std::size_t i = 0; i < manifest.entries.size(); ++i) {
    const Entry& entry = manifest.entries[i];
    bireg_cli::InputOptions input;
    input.path = entry.resolved;
    input.format = command.format;
    input.project = command.project;
    if (auto error = bireg_cli::read_input<G>(input, trajectories[i])) {
      return fail(*error + " (" + bireg_cli::where(manifest.name, entry.line) + ")");
    }
  }
  // Every subject's times on one clock: seconds after the earliest
  // timestamp of all subjects (a trajectory's own covariates start at its
  // own first timestamp).
  const io::Timestamp* origin = &trajectories.front().origin;
  for (const io::Trajectory<G>& trajectory : trajectories) {
    if (io::seconds_between(trajectory.origin, *origin) < 0) origin = &trajectory.origin;
  }
  std::vector<bireg::SubjectData<G>> subjects(trajectories.size());
  for (std::size_t i = 0; i < trajectories.size(); ++i) {
    subjects[i].observations = std::move(trajectories[i].observations);
    for (const io::Timestamp& t : trajectories[i].timestamps)
      subjects[i].covariates.push_back(io::seconds_between(t, *origin));
  }
  bireg::FitManyOptions<double> fit_options;
  fit_options.threads = command.threads;
  const bireg::FitManyResult<G> fits = bireg::fit_many<G>(
      bireg::GeodesicRegression<G>(bireg::RegressionOptions<double>()), subjects, fit_options);
  if (fits.status == bireg::Status::invalid_input && fits.fits.empty()) {
    return fail(manifest.name + ": " + fits.message);
  }
  std::vector<Trend> trends[2];
  std::vector<std::size_t> members[2], everyone;
  std::vector<Trend> all;
  std::string subjects_json = "[";
  for (std::size_t i = 0; i < manifest.entries.size(); ++i) {
    const Entry& entry = manifest.entries[i];
    const bireg::RegressionResult<G>& fit = fits.fits[i];
    subjects_json += std::string(i ? ", " : "") + "{\"path\": " + json_text(entry.path) +
                     ", \"cohort\": " + json_text(manifest.cohorts[entry.cohort]) +
                     ", \"subject\": " + json_text(entry.subject) +
                     ", \"status\": " + json_text(bireg::to_string(fit.status)) +
                     ", \"message\": " + json_text(fit.message) + "}";
    if (!fit.ok()) {
      std::fprintf(stderr, "bireg_compare: %s: the fit failed (%s%s%s); left out\n",
                   bireg_cli::where(manifest.name, entry.line).c_str(),
                   bireg::to_string(fit.status), fit.message.empty() ? "" : ": ",
                   fit.message.c_str());
      continue;
    }
    trends[entry.cohort].push_back(fits.trends[i]);
    members[entry.cohort].push_back(i);
    all.push_back(fits.trends[i]);
    everyone.push_back(i);
  }
  subjects_json += "]";
  const bireg::TwoSampleResult<bireg::Product<G, G>> result =
      bireg::compare_trends<G>(trends[0], trends[1], test_options(command));
  if (!result.ok()) {
    std::fprintf(stderr, "bireg_compare: %s: the trends cannot be compared: %s\n",
                 manifest.name.c_str(), result.message.c_str());
    return result.status == bireg::Status::invalid_input && fits.failed == 0 ? kExitInvalid
                                                                             : kExitNotConverged;
  }
  const std::size_t sizes[2] = {trends[0].size(), trends[1].size()};
  const std::optional<Trend> means[2] = {result.mean_a, result.mean_b};
  std::string json = test_json(command, result, "trends") + ", \"interval\": [" +
                     json_number(fits.t0) + ", " + json_number(fits.t1) +
                     "], \"cohorts\": " + cohorts_json(manifest, sizes, means) +
                     ", \"subjects\": " + subjects_json;
  if (command.population) {
    json += ", \"population\": {\"all\": " +
            population_json(bireg::population_trend<G>(all, fits.t0, fits.t1), everyone,
                            manifest.entries);
    for (std::size_t c = 0; c < 2; ++c) {
      json += ", " + json_text(manifest.cohorts[c]) + ": " +
              population_json(bireg::population_trend<G>(trends[c], fits.t0, fits.t1), members[c],
                              manifest.entries);
    }
    json += "}";
  }
  const int printed = print(json + "}");
  if (printed != 0) return printed;
  return fits.failed > 0 ? kExitNotConverged : 0;
}

template <class G>
int run(const Command& command) {
  Manifest manifest;
  if (auto error = read_manifest(command.manifest, manifest)) return fail(*error);
  return command.elements ? run_elements<G>(command, manifest) : run_trends<G>(command, manifest);
}

}  // namespace

int bireg_cli::compare_main(int argc, char** argv) {
  Command command;
  if (const auto error = parse_command(argc, argv, command)) {
    std::fprintf(stderr, "bireg_compare: %s\n%s", error->c_str(), kUsage);
    return kExitInvalid;
  }
  if (command.help) {
    std::printf("%s\n%s", kUsage, kHelp);
    return 0;
  }
  if (command.version) {
    std::printf("bireg_compare %s\n", bireg::version);
    return 0;
  }
  if (command.group == "SO2") return run<bireg::SO2<double>>(command);
  if (command.group == "SO3") return run<bireg::SO3<double>>(command);
  if (command.group == "SE2") return run<bireg::SE2<double>>(command);
  if (command.group == "SE3") return run<bireg::SE3<double>>(command);
  if (command.group == "GLp3") return run<bireg::GLp<3, double>>(command);
  std::fprintf(stderr, "bireg_compare: unknown group '%s' (SO2, SO3, SE2, SE3 or GLp3)\n%s",
               command.group.c_str(), kUsage);
  return kExitInvalid;
}
