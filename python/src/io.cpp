// The io layer: trajectory files (matrix, TUM, EuRoC, KITTI) read by the
// library's readers and formatted by its writers. A file the reader
// refuses raises ValueError with path:line and the reader's message.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "common.hpp"

#include "bireg/groups/tolerance.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/io/writers.hpp"

namespace bireg_python {
namespace {

template <class G>
nb::dict read(const std::string& path, const std::optional<bireg::io::Format>& format,
              bool project) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw nb::value_error(("cannot open '" + path + "' for reading").c_str());
  bireg::io::ReadOptions options;
  options.format = format;
  options.project = project && bireg::io::can_project<G>();
  bireg::io::Trajectory<G> trajectory;
  std::optional<bireg::io::ParseError> error;
  {
    nb::gil_scoped_release release;
    error = bireg::io::read_trajectory<G>(in, options, trajectory);
  }
  if (error) {
    const std::string where = error->line > 0 ? path + ":" + std::to_string(error->line) : path;
    throw nb::value_error((where + ": " + error->message).c_str());
  }
  const std::size_t count = trajectory.observations.size(), n = std::size_t(side<G>());
  NewArray y({count, n, n}), t({count});
  for (std::size_t i = 0; i < count; ++i) {
    write_row_major(trajectory.observations[i], y.data() + i * n * n);
    t.data()[i] = trajectory.covariates[i];
  }
  nb::list timestamps, lines;
  for (std::size_t i = 0; i < count; ++i) {
    timestamps.append(trajectory.timestamps[i].text);
    lines.append(trajectory.lines[i]);
  }
  nb::dict out;
  out["t"] = t.release();
  out["Y"] = y.release();
  out["origin"] = trajectory.origin.text;
  out["timestamps"] = timestamps;
  out["lines"] = lines;
  out["format"] = std::string(to_string(trajectory.format));
  out["projection_correction"] = trajectory.projection_correction;
  return out;
}

bireg::io::Format format_named(const std::string& name) {
  const std::optional<bireg::io::Format> format = bireg::io::format_from_string(name);
  if (!format)
    throw nb::value_error(
        ("unknown format '" + name + "': expected one of matrix, tum, euroc, kitti").c_str());
  return *format;
}

// The text of a trajectory file: Y[i] at timestamp texts[i] read in
// `source`'s time unit (converted exactly to `format`'s), or, with no
// texts, at t[i] seconds written as the shortest text that reads back to
// it. Refuses, naming the index, a pose that is not an element of G
// (is_element: finite, and in G),
// a time that is not finite and a text that is not a number. The GIL is
// released while it works.
template <class G>
std::string format_file(const Vector& t, const Stack& y, bireg::io::Format format,
                        const std::optional<std::vector<std::string>>& texts,
                        bireg::io::Format source) {
  if (!bireg::io::supports<G>(format))
    refuse(bireg::io::unsupported_format_message<G>(format) + " (use the matrix format)");
  const std::size_t count = y.shape(0);
  const StackView<G> view(y);
  std::string text, problem;
  {
    nb::gil_scoped_release release;
    std::vector<typename G::Element> poses(count);
    std::vector<bireg::io::Timestamp> times(count);
    const bireg::io::TimeUnit unit =
        texts ? bireg::io::time_unit(source) : bireg::io::TimeUnit::seconds;
    for (std::size_t i = 0; i < count && problem.empty(); ++i) {
      const std::string index = std::to_string(i);
      poses[i] = view[i];
      if (!G::is_element(poses[i], bireg::default_element_tolerance<double>())) {
        problem = "Y[" + index + "] is not an element of " + G::name;
      } else if (!texts && !std::isfinite(t.data()[i])) {
        problem = "t[" + index + "] is not finite";
      } else if (texts &&
                 std::any_of((*texts)[i].begin(), (*texts)[i].end(), bireg::io::is_separator)) {
        // parse_number would skip leading blanks (is_separator holds every
        // white space), and the text is written as it stands: a line break
        // would split the line.
        problem = "timestamp " + index + " holds a space, a separator or a line break";
      } else if (auto bad = bireg::io::parse_timestamp(
                     texts ? (*texts)[i] : bireg::io::format_double(t.data()[i]), unit, times[i])) {
        problem = "timestamp " + index + ": " + *bad;
      }
    }
    // Times from t are seconds: read them as a seconds format's are.
    if (problem.empty())
      text = bireg::io::format_trajectory<G>(format, texts ? source : bireg::io::Format::tum, times,
                                             poses);
  }
  if (!problem.empty()) refuse("write_trajectory: " + problem);
  return text;
}

}  // namespace

void bind_io(nb::module_& m) {
  m.def(
      "read_trajectory",
      [](const std::string& path, const std::string& group, const std::string& format,
         bool project) {
        std::optional<bireg::io::Format> chosen;
        if (!format.empty()) chosen = format_named(format);
        return with_group(group, [&](auto tag) -> nb::dict {
          using G = typename decltype(tag)::type;
          if (chosen && !bireg::io::reads<G>(*chosen))
            throw nb::value_error(bireg::io::unsupported_format_message<G>(*chosen).c_str());
          return read<G>(path, chosen, project);
        });
      },
      nb::arg("path"), nb::arg("group"), nb::arg("format"), nb::arg("project"),
      "bireg::io::read_trajectory<G>: t, Y, timestamps, lines, format.");
  m.def(
      "format_trajectory",
      [](const std::string& group, const Vector& t, const Stack& y, const std::string& format,
         const std::optional<std::vector<std::string>>& timestamps,
         const std::string& timestamps_format) {
        const bireg::io::Format target = format_named(format);
        const bireg::io::Format source = format_named(timestamps_format);
        if (t.shape(0) != y.shape(0) || (timestamps && timestamps->size() != y.shape(0)))
          refuse("write_trajectory: t, Y and timestamps differ in length");
        return with_group(group, [&](auto tag) {
          return format_file<typename decltype(tag)::type>(t, y, target, timestamps, source);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("Y"), nb::arg("format"), nb::arg("timestamps"),
      nb::arg("timestamps_format"),
      "bireg::io::format_trajectory<G>: the text of a trajectory file in `format`.");
}

}  // namespace bireg_python
