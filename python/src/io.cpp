// The io layer: trajectory files (matrix, TUM, EuRoC, KITTI) read by the
// library's readers. A file the reader refuses raises ValueError with
// path:line and the reader's message.
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

#include <nanobind/stl/string.h>

#include "common.hpp"

#include "bireg/io/formats.hpp"

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

}  // namespace

void bind_io(nb::module_& m) {
  m.def(
      "read_trajectory",
      [](const std::string& path, const std::string& group, const std::string& format,
         bool project) {
        std::optional<bireg::io::Format> chosen;
        if (!format.empty()) {
          chosen = bireg::io::format_from_string(format);
          if (!chosen)
            throw nb::value_error(
                ("unknown format '" + format + "': expected one of matrix, tum, euroc, kitti")
                    .c_str());
        }
        return with_group(group, [&](auto tag) -> nb::dict {
          using G = typename decltype(tag)::type;
          if (chosen && !bireg::io::reads<G>(*chosen))
            throw nb::value_error(bireg::io::unsupported_format_message<G>(*chosen).c_str());
          return read<G>(path, chosen, project);
        });
      },
      nb::arg("path"), nb::arg("group"), nb::arg("format"), nb::arg("project"),
      "bireg::io::read_trajectory<G>: t, Y, timestamps, lines, format.");
}

}  // namespace bireg_python
