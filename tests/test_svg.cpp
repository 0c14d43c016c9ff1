// examples/svg_plot.hpp, the demo's plotter: nice_ticks() gives round,
// equally spaced ticks covering the range for any input; render_svg() gives
// well-formed XML (checked by a small parser below) whose tick labels are
// round numbers, also for hostile labels and non-finite data; the demo's
// pictures in docs/ pass the same checks.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "catch.hpp"
#include "svg_plot.hpp"

#ifndef BIREG_DOCS_DIR
#error "BIREG_DOCS_DIR must name the docs/ directory holding the demo's pictures"
#endif

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

double decimal(long long digits, int exponent) {
  return std::strtod((std::to_string(digits) + "e" + std::to_string(exponent)).c_str(), nullptr);
}

// Why `ticks` are not k * m * 10^e for consecutive integers k, m in {1, 2, 5},
// each exactly the double nearest to that decimal; nullopt if they are.
// The step's mantissa is read from the mean spacing of the outer ticks,
// whose rounding is at most |tick| * 2^-53 each, so relative to the step at
// most (|tick| / step) * 2^-52: largest for the 1e-9 wide range at 1 (step
// 1e-10, |tick| / step = 1e10), 1e10 * 2.2e-16 = 2.2e-6, below the 1e-4
// used; and 1, 2 and 5 are a factor 2 apart, so the mantissa cannot be
// mistaken. The ticks themselves are then compared
// exactly: the claim is that they are the decimals, not close to them.
std::optional<std::string> not_round(const std::vector<double>& ticks) {
  if (ticks.size() < 2) return "fewer than 2 ticks";
  const double spacing = (ticks.back() - ticks.front()) / static_cast<double>(ticks.size() - 1);
  if (!(spacing > 0)) return "not increasing";
  const int exponent = static_cast<int>(std::floor(std::log10(spacing * (1 + 1e-4))));
  const double scaled = spacing / std::pow(10.0, exponent);
  const long long mantissa = std::llround(scaled);
  if ((mantissa != 1 && mantissa != 2 && mantissa != 5) ||
      std::abs(scaled - static_cast<double>(mantissa)) > 1e-4) {
    return "spacing " + std::to_string(spacing) + " is not 1, 2 or 5 times a power of ten";
  }
  const double step = decimal(mantissa, exponent);
  const long long first = std::llround(ticks.front() / step);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    const long long k = first + static_cast<long long>(i);
    if (ticks[i] != decimal(k * mantissa, exponent)) {
      char buffer[160];
      std::snprintf(buffer, sizeof buffer, "tick %zu = %.17g is not %lld * %lld e%d", i, ticks[i],
                    k, mantissa, exponent);
      return std::string(buffer);
    }
  }
  return std::nullopt;
}

// nice_ticks' documented contract for a finite, ordered, non-degenerate
// range: round, covering, the outer ticks the nearest ones, and between 3
// and target + 2 of them.
void check_ticks(double lo, double hi, int target) {
  INFO("range [" << lo << ", " << hi << "], target " << target);
  const std::vector<double> ticks = bireg_plot::nice_ticks(lo, hi, target);
  const auto problem = not_round(ticks);
  INFO((problem ? *problem : std::string("round")));
  REQUIRE(!problem);
  CHECK(ticks.size() >= 3);
  CHECK(ticks.size() <= static_cast<std::size_t>(target) + 2);
  CHECK(ticks.front() <= lo);
  CHECK(ticks.back() >= hi);
  CHECK(ticks[1] > lo);                 // the first tick is the last one at or below lo
  CHECK(ticks[ticks.size() - 2] < hi);  // and the last the first at or above hi
}

// Why `svg` is not well-formed XML of the subset render_svg writes (one root
// element, quoted attributes, only the five predefined entities, no raw '<'
// in text or attributes), or contains "nan"/"inf" as a word; nullopt if none.
std::optional<std::string> not_well_formed(const std::string& svg) {
  const auto bad_content = [](const std::string& text) -> std::optional<std::string> {
    static const std::set<std::string> entities = {"amp", "lt", "gt", "quot", "apos"};
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] == '<') return "raw '<' in \"" + text + "\"";
      if (text[i] == '&') {
        const std::size_t end = text.find(';', i);
        if (end == std::string::npos || !entities.count(text.substr(i + 1, end - i - 1))) {
          return "bad entity in \"" + text + "\"";
        }
      }
      if (std::isalpha(static_cast<unsigned char>(text[i])) &&
          (i == 0 || !std::isalpha(static_cast<unsigned char>(text[i - 1])))) {
        std::string word;
        for (std::size_t j = i;
             j < text.size() && std::isalpha(static_cast<unsigned char>(text[j])); ++j) {
          word += static_cast<char>(std::tolower(static_cast<unsigned char>(text[j])));
        }
        if (word == "nan" || word == "inf" || word == "infinity") return "\"" + word + "\" written";
      }
    }
    return std::nullopt;
  };
  const auto is_name_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '-' ||
           c == '.';
  };
  std::size_t pos = 0;
  if (svg.compare(0, 5, "<?xml") == 0) {
    pos = svg.find("?>");
    if (pos == std::string::npos) return "unterminated XML declaration";
    pos += 2;
  }
  std::vector<std::string> open;
  int roots = 0;
  while (pos < svg.size()) {
    const std::size_t lt = svg.find('<', pos);
    const std::string text =
        svg.substr(pos, lt == std::string::npos ? std::string::npos : lt - pos);
    if (open.empty() && text.find_first_not_of(" \t\r\n") != std::string::npos) {
      return "text outside the root element";
    }
    if (auto problem = bad_content(text)) return problem;
    if (lt == std::string::npos) break;
    pos = lt + 1;
    const bool closing = pos < svg.size() && svg[pos] == '/';
    if (closing) ++pos;
    const std::size_t name_start = pos;
    while (pos < svg.size() && is_name_char(svg[pos]))
      ++pos;
    const std::string name = svg.substr(name_start, pos - name_start);
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return "bad tag name";
    if (closing) {
      if (pos >= svg.size() || svg[pos] != '>') return "bad closing tag </" + name;
      if (open.empty() || open.back() != name) return "</" + name + "> does not close an open tag";
      open.pop_back();
      ++pos;
      continue;
    }
    if (open.empty() && ++roots > 1) return "more than one root element";
    std::set<std::string> attributes;
    while (true) {
      const std::size_t space = pos;
      while (pos < svg.size() && std::isspace(static_cast<unsigned char>(svg[pos])))
        ++pos;
      if (pos >= svg.size()) return "unterminated tag <" + name;
      if (svg[pos] == '>') {
        open.push_back(name);
        ++pos;
        break;
      }
      if (svg.compare(pos, 2, "/>") == 0) {
        pos += 2;
        break;
      }
      if (pos == space) return "attributes of <" + name + " not separated by space";
      const std::size_t attribute_start = pos;
      while (pos < svg.size() && is_name_char(svg[pos]))
        ++pos;
      const std::string attribute = svg.substr(attribute_start, pos - attribute_start);
      if (attribute.empty()) return "bad attribute in <" + name;
      if (!attributes.insert(attribute).second) return "repeated attribute " + attribute;
      if (pos + 1 >= svg.size() || svg[pos] != '=' ||
          (svg[pos + 1] != '"' && svg[pos + 1] != '\'')) {
        return "attribute " + attribute + " of <" + name + " not quoted";
      }
      const char quote = svg[pos + 1];
      const std::size_t value_end = svg.find(quote, pos + 2);
      if (value_end == std::string::npos) return "unterminated attribute " + attribute;
      if (auto problem = bad_content(svg.substr(pos + 2, value_end - pos - 2))) return problem;
      pos = value_end + 1;
    }
  }
  if (!open.empty()) return "<" + open.back() + "> not closed";
  if (roots != 1) return "no root element";
  return std::nullopt;
}

// Tick labels per axis, in document order: each run of <text class="tick x">
// (or "tick y") labels is one axis.
std::vector<std::vector<std::string>> tick_labels(const std::string& svg) {
  static const std::regex tick("<text class=\"tick ([xy])\"[^>]*>([^<]*)</text>");
  std::vector<std::vector<std::string>> axes;
  std::string previous;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), tick); it != std::sregex_iterator();
       ++it) {
    if ((*it)[1] != previous || axes.empty()) axes.emplace_back();
    previous = (*it)[1];
    axes.back().push_back((*it)[2]);
  }
  return axes;
}

// Every axis has at least 3 labels, each a number read in full, and together
// round ticks (not_round); every font is at least 12 px.
void check_labels_and_fonts(const std::string& svg) {
  const auto axes = tick_labels(svg);
  REQUIRE(!axes.empty());
  for (const auto& labels : axes) {
    std::vector<double> values;
    for (const std::string& label : labels) {
      char* end = nullptr;
      values.push_back(std::strtod(label.c_str(), &end));
      INFO("label \"" << label << "\"");
      REQUIRE(!label.empty());
      REQUIRE(*end == '\0');
    }
    CHECK(values.size() >= 3);
    const auto problem = not_round(values);
    INFO((problem ? *problem : std::string("round")));
    CHECK(!problem);
  }
  static const std::regex font("font-size=\"([0-9.]+)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), font); it != std::sregex_iterator();
       ++it) {
    CHECK(std::stod((*it)[1]) >= 12);
  }
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("nice_ticks: round, covering, 3 to target + 2 ticks over many ranges") {
  const std::vector<std::pair<double, double>> ranges = {
      {0, 1},        {0.3, 0.7},     {-3.2, 7.9},  {-7.3, -2.1},     {-0.3, 0.7},  {1, 1 + 1e-9},
      {-1e-9, 0},    {0, 1e-9},      {2e-9, 3e-9}, {0, 1e9},         {-1e9, 1e9},  {1e9, 2e9},
      {25.75, 26.5}, {-93.1, 170.2}, {0.1, 0.3},   {1234.5, 1234.6}, {-1e-6, 1e-6}};
  for (int target = 3; target <= 10; ++target) {
    for (const auto& [lo, hi] : ranges)
      check_ticks(lo, hi, target);
  }
  // Random ranges: widths log-uniform over 1e-9 .. 1e9, centres up to 1e4
  // widths away (above that the width falls below 1e-12 of the magnitude,
  // where nice_ticks widens the range by design: tested below).
  std::mt19937 random(17);
  std::uniform_real_distribution<double> log_width(-9, 9), offset(-1e4, 1e4);
  std::uniform_int_distribution<int> target(3, 10);
  for (int trial = 0; trial < 3000; ++trial) {
    const double width = std::pow(10.0, log_width(random));
    const double lo = offset(random) * width;
    check_ticks(lo, lo + width, target(random));
  }
}

TEST_CASE("nice_ticks: lo == hi, reversed and non-finite input as documented") {
  for (double value : {0.0, 5.0, -3.0, 1e-7, 1e12, 0.3}) {
    INFO("value " << value);
    const std::vector<double> ticks = bireg_plot::nice_ticks(value, value);
    REQUIRE(!not_round(ticks));
    CHECK(ticks.size() >= 3);
    CHECK(ticks.front() < value);  // widened to value +- 10% (+- 1 about 0)
    CHECK(ticks.back() > value);
    const double half = value == 0 ? 1.0 : 0.1 * std::abs(value);
    CHECK(ticks.front() <= value - half);
    CHECK(ticks.back() >= value + half);
  }
  // A width below 1e-12 of the magnitude is treated as a single value.
  CHECK(bireg_plot::nice_ticks(1e6, 1e6 * (1 + 1e-14)) == bireg_plot::nice_ticks(1e6, 1e6));
  CHECK(bireg_plot::nice_ticks(7, -2) == bireg_plot::nice_ticks(-2, 7));
  CHECK(bireg_plot::nice_ticks(7, -2, 8) == bireg_plot::nice_ticks(-2, 7, 8));
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{
           {kNaN, 1}, {0, kNaN}, {-kInf, 0}, {0, kInf}, {kNaN, kNaN}, {-1e308, 1e308}}) {
    CHECK(bireg_plot::nice_ticks(lo, hi).empty());
  }
  // Targets outside [3, 20] are clamped: never fewer than 3 ticks.
  CHECK(bireg_plot::nice_ticks(0, 1, 0).size() >= 3);
  CHECK(bireg_plot::nice_ticks(0, 1, -5).size() >= 3);
  CHECK(bireg_plot::nice_ticks(0, 1, 1000).size() <= 22);
}

TEST_CASE("The XML checker rejects what it must") {
  CHECK(!not_well_formed("<svg a=\"1\"><g><text>x &amp; y</text></g><rect/></svg>\n"));
  CHECK(not_well_formed("<svg><g></svg>"));
  CHECK(not_well_formed("<svg><g></g>"));
  CHECK(not_well_formed("<svg a=1></svg>"));
  CHECK(not_well_formed("<svg a=\"1\"b=\"2\"></svg>"));
  CHECK(not_well_formed("<svg a=\"1\" a=\"2\"></svg>"));
  CHECK(not_well_formed("<svg><text>a & b</text></svg>"));
  CHECK(not_well_formed("<svg><text>&nbsp;</text></svg>"));
  CHECK(not_well_formed("<svg><text>a < b</text></svg>"));
  CHECK(not_well_formed("<svg x=\"nan\"></svg>"));
  CHECK(not_well_formed("<svg><text>-inf</text></svg>"));
  CHECK(not_well_formed("<svg></svg><svg></svg>"));
  CHECK(not_well_formed("text<svg></svg>"));
  CHECK(!not_well_formed("<svg><text>information, nanometre</text></svg>"));
  CHECK(not_round({0, 0.1, 0.30000000000000004}));
  CHECK(not_round({0, 0.3, 0.6}));
  CHECK(not_round({0, 0.2, 0.5}));
}

TEST_CASE("render_svg: well-formed XML with round tick labels, for hostile input") {
  const std::string hostile = "a<b & \"c\" 'd' ]]> \x01";
  bireg_plot::Figure figure;
  figure.title = hostile;
  figure.subtitle = hostile;
  bireg_plot::Panel data;
  data.title = hostile;
  data.x_label = "time";
  data.x_unit = "s";
  data.y_label = hostile;
  data.y_unit = "<deg>";
  data.series.push_back({hostile, "#d62728", {0, 0.1, 0.2, 0.3, 0.4}, {1, kNaN, 3, kInf, 2}, true});
  data.series.push_back({"fit", "red\"", {0, 0.1, 0.2, kNaN, 0.4, 0.5}, {1, 2, 3, 4, -kInf, 2}});
  data.series.push_back({"dashed", "#333", {0, 0.5}, {0, 0}, false, true});
  data.series.push_back({"empty", "#000", {}, {}});
  data.series.push_back({"all non-finite", "#000", {kNaN, kNaN}, {kNaN, kNaN}});
  data.series.push_back({"short y", "#000", {0, 1, 2}, {1}});
  data.bands.push_back(
      {hostile, "#1f77b4", {0, 0.1, 0.2, 0.3, 0.4}, {0, 1, kNaN, 1, 1}, {2, 3, 4, kInf, 3}});
  data.bands.push_back({"empty band", "#1f77b4", {}, {}, {}});
  figure.panels.push_back(data);
  figure.panels.push_back({});  // no data at all: a default axis
  bireg_plot::Panel tiny;       // a range of 1e-9 about 1
  tiny.x_label = "x";
  tiny.y_label = "y";
  tiny.series.push_back({"s", "#000", {-1e9, 1e9}, {1, 1 + 1e-9}});
  figure.panels.push_back(tiny);

  const std::string svg = bireg_plot::render_svg(figure);
  const auto problem = not_well_formed(svg);
  INFO((problem ? *problem : std::string("well-formed")));
  REQUIRE(!problem);
  CHECK(svg.find("a&lt;b &amp; &quot;c&quot; &apos;d&apos; ]]&gt;") != std::string::npos);
  CHECK(svg.find("time [s]") != std::string::npos);
  CHECK(svg.find("[&lt;deg&gt;]") != std::string::npos);
  CHECK(svg.find(">empty</text>") != std::string::npos);  // in the legend though empty
  CHECK(svg.find(">empty band</text>") != std::string::npos);
  check_labels_and_fonts(svg);
  CHECK(tick_labels(svg).size() == 6);  // x and y of each of the three panels

  // The first series' finite points are dots; NaN and inf ones are skipped.
  const std::regex dot("<circle cx=\"[^\"]+\" cy=\"[^\"]+\" r=\"2.3\" fill=\"#d62728\"/>");
  const auto dots =
      std::distance(std::sregex_iterator(svg.begin(), svg.end(), dot), std::sregex_iterator());
  CHECK(dots == 3);
}

TEST_CASE("render_svg: an empty figure is well-formed") {
  const std::string svg = bireg_plot::render_svg({});
  CHECK(!not_well_formed(svg));
}

TEST_CASE("The demo's pictures in docs/ are well-formed, with round ticks and units") {
  for (const char* name : {"demo_so3_imu.svg", "demo_se3_walk.svg"}) {
    const std::string path = std::string(BIREG_DOCS_DIR) + "/" + name;
    INFO(path);
    const std::string svg = read_file(path);
    REQUIRE(!svg.empty());
    const auto problem = not_well_formed(svg);
    INFO((problem ? *problem : std::string("well-formed")));
    REQUIRE(!problem);
    check_labels_and_fonts(svg);
    CHECK(svg.find("time [s]") != std::string::npos);
    CHECK(svg.find("[deg]") != std::string::npos);
    CHECK(svg.find("95% band</text>") != std::string::npos);
    CHECK(svg.find(" data</text>") != std::string::npos);
    CHECK(svg.find(" fit</text>") != std::string::npos);
  }
}

TEST_CASE("The gyroscope demo's picture in docs/ is well-formed, with round ticks and units") {
  const std::string svg = read_file(std::string(BIREG_DOCS_DIR) + "/gyro_demo.svg");
  REQUIRE(!svg.empty());
  const auto problem = not_well_formed(svg);
  INFO((problem ? *problem : std::string("well-formed")));
  REQUIRE(!problem);
  check_labels_and_fonts(svg);
  CHECK(svg.find("time [s]") != std::string::npos);
  CHECK(svg.find("[rad/s]") != std::string::npos);
  for (const char* legend : {">gyroscope</text>", ">finite differences</text>", ">bireg</text>"})
    CHECK(svg.find(legend) != std::string::npos);
}
