// bireg_plot: a small SVG plotter for the examples (not part of the installed
// library; it needs the standard library only). A Figure is a title and a
// column of Panels; each Panel plots Series (lines or dots) and Bands
// (filled, semi-transparent regions between two curves) against round axis
// ticks, with units on both axes and a legend naming every series and band.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace bireg_plot {

// Round tick values covering [lo, hi].
//
// Ticks are k * m * 10^e for consecutive integers k, with m in {1, 2, 5},
// running from the last multiple of the step at or below lo to the first at
// or above hi (the axis spans exactly the outer ticks). Why a step always
// exists: let raw = (hi - lo) / target and u = 10^floor(log10 raw), raw in
// [u, 10u). The smallest of u, 2u, 5u, 10u not below raw is step < 2.5 raw
// (consecutive candidates are at most 2.5 apart), so the number of intervals
// n satisfies target / 2.5 < n <= target + 1, i.e. 3 to target + 2 ticks for
// target clamped to [3, 20] (3 to 7 for the default 5). Among all candidates
// m * 10^e, e within one of log10 raw, whose tick count is in that range, the
// one with the shortest axis is taken: 0 .. 1.27 gets 0 .. 1.4 in steps of
// 0.2, not 0 .. 1.5 in steps of 0.5. Each tick is the double nearest to the
// decimal k * m * 10^e (parsed from its decimal text, not accumulated), so it
// prints back as that decimal with no float noise.
//
// Edge cases: reversed input is swapped; lo == hi (or a range narrower than
// 1e-12 of its magnitude, below what doubles resolve for ticks) is widened to
// lo +- 10% (+- 1 about zero); a non-finite bound, a width that
// overflows, or magnitudes beyond 1e+-300 give an empty vector.
inline std::vector<double> nice_ticks(double lo, double hi, int target = 5);

struct Series {
  std::string label;
  std::string colour;
  std::vector<double> x, y;  // pairs up to the shorter length
  bool points = false;       // dots instead of a line
  bool dashed = false;
};

struct Band {  // filled, semi-transparent, between lower and upper
  std::string label;
  std::string colour;
  std::vector<double> x, lower, upper;
};

struct Panel {
  std::string title;
  std::string x_label, x_unit, y_label, y_unit;
  std::vector<Band> bands;
  std::vector<Series> series;
};

struct Figure {
  std::string title;
  std::string subtitle;
  double width = 760;
  double panel_height = 260;  // the legend holds about (panel_height - 80) / 18 entries
  std::vector<Panel> panels;
};

// Well-formed XML: text is escaped, non-finite points are skipped (a line or
// band is split there), empty series draw nothing but keep their legend entry.
inline std::string render_svg(const Figure& figure);

// ---- implementation ---------------------------------------------------------

namespace detail {

// printf into a string; only numbers and fixed markup go through here, text
// is escaped and appended separately, so 256 characters always suffice.
template <class... Args>
std::string format(const char* pattern, Args... args) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, pattern, args...);
  return buffer;
}

inline double parse_decimal(long long digits, int exponent) {
  return std::strtod((std::to_string(digits) + "e" + std::to_string(exponent)).c_str(), nullptr);
}

// `value` in %e form with the fewest significant digits (1..17) that read
// back as `value`, and those digits' count.
inline std::string shortest_scientific(double value, int& digits) {
  std::string text;
  for (digits = 1; digits <= 17; ++digits) {
    text = format("%.*e", digits - 1, value);
    if (std::strtod(text.c_str(), nullptr) == value) break;
  }
  return text;
}

// Labels for one axis, in one notation: fixed with a common number of
// decimals ("0.5", "1.0", "1.5") unless the values are large or small, then
// shortest scientific ("2.5e-7").
inline std::vector<std::string> format_ticks(const std::vector<double>& ticks) {
  double largest = 0;
  int decimals = 0, digits = 0;
  for (double tick : ticks) {
    largest = std::max(largest, std::abs(tick));
    const std::string text = shortest_scientific(tick, digits);
    const int exponent = std::atoi(text.c_str() + text.find('e') + 1);
    decimals = std::max(decimals, digits - 1 - exponent);
  }
  const bool scientific = largest >= 1e6 || (largest > 0 && largest < 1e-3);
  std::vector<std::string> labels;
  for (double tick : ticks) {
    if (!scientific) {
      labels.push_back(format("%.*f", decimals, tick == 0 ? 0.0 : tick));  // no "-0.0"
    } else if (tick == 0) {
      labels.emplace_back("0");
    } else {
      const std::string text = shortest_scientific(tick, digits);
      const std::size_t e = text.find('e');
      labels.push_back(text.substr(0, e) + "e" + std::to_string(std::atoi(text.c_str() + e + 1)));
    }
  }
  return labels;
}

inline std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    const unsigned char code = static_cast<unsigned char>(c);
    if (c == '&' || c == '<' || c == '>' || c == '"' || c == '\'') {
      out += c == '&'   ? "&amp;"
             : c == '<' ? "&lt;"
             : c == '>' ? "&gt;"
             : c == '"' ? "&quot;"
                        : "&apos;";
    } else {  // XML 1.0 forbids control characters other than tab and newline
      out += code < 0x20 && c != '\t' && c != '\n' ? ' ' : c;
    }
  }
  return out;
}

inline std::string axis_label(const std::string& label, const std::string& unit) {
  return escape(unit.empty() ? label : label + " [" + unit + "]");
}

// The finite range of some values; nice ticks over it, [0, 1] if it is empty.
struct Extent {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(const std::vector<double>& values) {
    for (double v : values) {
      if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    }
  }
  std::vector<double> ticks(int target) const {
    std::vector<double> t = lo <= hi ? nice_ticks(lo, hi, target) : std::vector<double>{};
    return t.empty() ? nice_ticks(0, 1, target) : t;
  }
};

// Data to pixels in one panel's plot area, which spans the outer ticks.
struct Frame {
  std::vector<double> x_ticks, y_ticks;
  double left, top, width, height;
  double px(double x) const {
    return left + (x - x_ticks.front()) / (x_ticks.back() - x_ticks.front()) * width;
  }
  double py(double y) const {
    return top + (y_ticks.back() - y) / (y_ticks.back() - y_ticks.front()) * height;
  }
  // "px,py " or, for a point that does not map to a finite pixel, "".
  std::string point(double x, double y) const {
    const double u = px(x), v = py(y);
    return std::isfinite(u) && std::isfinite(v) ? format("%.2f,%.2f ", u, v) : std::string();
  }
};

inline std::string axes(const Panel& panel, const Frame& frame) {
  const double right = frame.left + frame.width, bottom = frame.top + frame.height;
  std::string svg = format("<text x=\"%.0f\" y=\"%.0f\" font-size=\"14\" font-weight=\"bold\">",
                           frame.left, frame.top - 10) +
                    escape(panel.title) + "</text>\n";
  const std::vector<std::string> x_labels = format_ticks(frame.x_ticks);
  const std::vector<std::string> y_labels = format_ticks(frame.y_ticks);
  for (std::size_t k = 0; k < x_labels.size(); ++k) {
    const double x = frame.px(frame.x_ticks[k]);
    svg += format("<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"#e4e4e4\"/>\n", x,
                  frame.top, x, bottom) +
           format(
               "<text class=\"tick x\" x=\"%.2f\" y=\"%.2f\" font-size=\"12\" "
               "text-anchor=\"middle\">",
               x, bottom + 16) +
           x_labels[k] + "</text>\n";
  }
  for (std::size_t k = 0; k < y_labels.size(); ++k) {
    const double y = frame.py(frame.y_ticks[k]);
    svg += format("<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"#e4e4e4\"/>\n",
                  frame.left, y, right, y) +
           format(
               "<text class=\"tick y\" x=\"%.2f\" y=\"%.2f\" font-size=\"12\" "
               "text-anchor=\"end\">",
               frame.left - 6, y + 4) +
           y_labels[k] + "</text>\n";
  }
  const double middle = frame.top + frame.height / 2;
  return svg +
         format(
             "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"none\" "
             "stroke=\"#888\"/>\n",
             frame.left, frame.top, frame.width, frame.height) +
         format("<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\">", frame.left + frame.width / 2,
                bottom + 36) +
         axis_label(panel.x_label, panel.x_unit) + "</text>\n" +
         format(
             "<text x=\"20\" y=\"%.2f\" transform=\"rotate(-90 20 %.2f)\" "
             "text-anchor=\"middle\">",
             middle, middle) +
         axis_label(panel.y_label, panel.y_unit) + "</text>\n";
}

// One polygon per run of points where x, lower and upper are all finite:
// along the upper curve, then back along the lower one.
inline std::string band(const Band& band, const Frame& frame) {
  const std::size_t n = std::min({band.x.size(), band.lower.size(), band.upper.size()});
  std::string svg, upper, lower;
  std::size_t run = 0;
  for (std::size_t i = 0; i <= n; ++i) {
    const std::string top = i < n ? frame.point(band.x[i], band.upper[i]) : "";
    const std::string bottom = i < n ? frame.point(band.x[i], band.lower[i]) : "";
    if (!top.empty() && !bottom.empty()) {
      upper += top;
      lower.insert(0, bottom);
      ++run;
      continue;
    }
    if (run >= 2) {  // a gap or the end closes the run
      svg += "<polygon points=\"" + upper + lower + "\" fill=\"" + escape(band.colour) +
             "\" fill-opacity=\"0.22\" stroke=\"none\"/>\n";
    }
    upper.clear();
    lower.clear();
    run = 0;
  }
  return svg;
}

// Dots, or one polyline per run of finite points.
inline std::string series(const Series& series, const Frame& frame) {
  const std::size_t n = std::min(series.x.size(), series.y.size());
  const std::string colour = escape(series.colour);
  std::string svg, points;
  for (std::size_t i = 0; i <= n; ++i) {
    const std::string point = i < n ? frame.point(series.x[i], series.y[i]) : "";
    if (series.points && !point.empty()) {
      svg += format("<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.3\" fill=\"", frame.px(series.x[i]),
                    frame.py(series.y[i])) +
             colour + "\"/>\n";
    } else if (!point.empty()) {
      points += point;
    } else if (!points.empty()) {  // a gap or the end closes the run
      svg += "<polyline points=\"" + points + "\" fill=\"none\" stroke=\"" + colour +
             "\" stroke-width=\"1.8\"" + (series.dashed ? " stroke-dasharray=\"6 4\"" : "") +
             "/>\n";
      points.clear();
    }
  }
  return svg;
}

// Right of the plot, one row per series (its mark) and band (a swatch).
inline std::string legend(const Panel& panel, const Frame& frame) {
  const double x = frame.left + frame.width + 14;
  double y = frame.top + 12;
  std::string svg;
  const auto label = [&](const std::string& text) {
    svg += format("<text x=\"%.2f\" y=\"%.2f\" font-size=\"12\">", x + 26, y) + escape(text) +
           "</text>\n";
    y += 18;
  };
  for (const Series& s : panel.series) {
    svg += s.points ? format("<circle cx=\"%.2f\" cy=\"%.2f\" r=\"3\" fill=\"", x + 10, y - 4)
                    : format(
                          "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" "
                          "stroke-width=\"1.8\"%s stroke=\"",
                          x, y - 4, x + 20, y - 4, s.dashed ? " stroke-dasharray=\"6 4\"" : "");
    svg += escape(s.colour) + "\"/>\n";
    label(s.label);
  }
  for (const Band& b : panel.bands) {
    svg += format(
               "<rect x=\"%.2f\" y=\"%.2f\" width=\"20\" height=\"10\" fill-opacity=\"0.22\" "
               "fill=\"",
               x, y - 9) +
           escape(b.colour) + "\"/>\n";
    label(b.label);
  }
  return svg;
}

}  // namespace detail

inline std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {};
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {
    const double half = lo != 0 ? 0.1 * std::abs(lo) : 1.0;
    hi = lo + half;
    lo -= half;
  }
  target = std::clamp(target, 3, 20);
  const double raw = (hi - lo) / target;
  if (!std::isfinite(raw) || raw < 1e-300 || raw > 1e300) return {};
  // Candidates m * 10^e around raw; keep the one whose outer ticks span the
  // least (the tightest axis) among those giving 3 .. target + 2 ticks.
  const int raw_exponent = static_cast<int>(std::floor(std::log10(raw)));
  int mantissa = 0, exponent = 0;
  double best_span = std::numeric_limits<double>::infinity();
  for (int e = raw_exponent - 1; e <= raw_exponent + 1; ++e) {
    for (int m : {1, 2, 5}) {
      const double candidate = m * std::pow(10.0, e);
      const double intervals = std::ceil(hi / candidate) - std::floor(lo / candidate);
      if (intervals >= 2 && intervals <= target + 1 && intervals * candidate < best_span) {
        best_span = intervals * candidate;
        mantissa = m;
        exponent = e;
      }
    }
  }
  if (mantissa == 0) return {};
  const double step = detail::parse_decimal(mantissa, exponent);
  // One extra tick each side absorbs rounding in lo / step; the trim below
  // keeps exactly one tick at or beyond each end.
  const long long first = static_cast<long long>(std::floor(lo / step)) - 1;
  const long long last = static_cast<long long>(std::ceil(hi / step)) + 1;
  std::vector<double> ticks;
  for (long long k = first; k <= last; ++k) {
    ticks.push_back(detail::parse_decimal(k * mantissa, exponent));
    if (!std::isfinite(ticks.back())) return {};
  }
  while (ticks.size() > 2 && ticks[1] <= lo)
    ticks.erase(ticks.begin());
  while (ticks.size() > 2 && ticks[ticks.size() - 2] >= hi)
    ticks.pop_back();
  return ticks;
}

inline std::string render_svg(const Figure& figure) {
  const double left = 80, legend_width = 160, header = figure.subtitle.empty() ? 40 : 62;
  const double plot_width = std::max(figure.width - left - legend_width, 100.0);
  const double plot_height = std::max(figure.panel_height - 80, 40.0);
  const double height = header + figure.panels.size() * figure.panel_height + 8;
  std::string svg = detail::format(
                        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg "
                        "xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                        "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"13\">\n",
                        figure.width, height, figure.width, height) +
                    "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n" +
                    "<text x=\"16\" y=\"26\" font-size=\"17\" font-weight=\"bold\">" +
                    detail::escape(figure.title) + "</text>\n";
  if (!figure.subtitle.empty()) {
    svg += "<text x=\"16\" y=\"48\" fill=\"#444\">" + detail::escape(figure.subtitle) + "</text>\n";
  }
  for (std::size_t p = 0; p < figure.panels.size(); ++p) {
    const Panel& panel = figure.panels[p];
    detail::Extent x, y;
    for (const Band& b : panel.bands) {
      x.add(b.x);
      y.add(b.lower);
      y.add(b.upper);
    }
    for (const Series& s : panel.series) {
      x.add(s.x);
      y.add(s.y);
    }
    const double top = header + p * figure.panel_height + 30;
    const detail::Frame frame{x.ticks(6), y.ticks(5), left, top, plot_width, plot_height};
    svg += detail::axes(panel, frame);
    for (const Band& b : panel.bands)
      svg += detail::band(b, frame);  // under the series
    for (const Series& s : panel.series)
      svg += detail::series(s, frame);
    svg += detail::legend(panel, frame);
  }
  return svg + "</svg>\n";
}

}  // namespace bireg_plot
