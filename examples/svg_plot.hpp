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
std::vector<double> nice_ticks(double lo, double hi, int target = 5);

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
std::string render_svg(const Figure& figure);

// ---- implementation ---------------------------------------------------------

namespace detail {

inline double parse_decimal(long long digits, int exponent) {
  const std::string text = std::to_string(digits) + "e" + std::to_string(exponent);
  return std::strtod(text.c_str(), nullptr);
}

// The fewest significant digits (1..17) that read back as `value`, in %e form.
inline std::string shortest_scientific(double value) {
  char buffer[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*e", digits - 1, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  return buffer;
}

// Labels for one axis, in one notation: fixed with a common number of
// decimals ("0.5", "1.0", "1.5") unless the values are large or small.
inline std::vector<std::string> format_ticks(const std::vector<double>& ticks) {
  double largest = 0;
  for (double tick : ticks)
    largest = std::max(largest, std::abs(tick));
  const bool scientific = largest >= 1e6 || (largest > 0 && largest < 1e-3);
  int decimals = 0;
  for (double tick : ticks) {
    const std::string shortest = shortest_scientific(tick);
    const std::size_t e = shortest.find('e');
    const bool has_point = shortest.find('.') != std::string::npos;
    const int digits = static_cast<int>(e) - (tick < 0 ? 1 : 0) - (has_point ? 1 : 0);
    const int exponent = std::atoi(shortest.c_str() + e + 1);
    decimals = std::max(decimals, digits - 1 - exponent);
  }
  std::vector<std::string> labels;
  for (double tick : ticks) {
    char buffer[64];
    if (tick == 0) {
      std::snprintf(buffer, sizeof buffer, scientific ? "0" : "%.*f", decimals, 0.0);
    } else if (scientific) {  // "2.5e-07" -> "2.5e-7"
      std::string text = shortest_scientific(tick);
      const std::size_t e = text.find('e');
      const int exponent = std::atoi(text.c_str() + e + 1);
      std::snprintf(buffer, sizeof buffer, "%se%d", text.substr(0, e).c_str(), exponent);
    } else {
      std::snprintf(buffer, sizeof buffer, "%.*f", decimals, tick);
    }
    labels.emplace_back(buffer);
  }
  return labels;
}

inline std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:  // XML 1.0 forbids control characters other than tab and newlines
        out += (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n') ? ' ' : c;
    }
  }
  return out;
}

inline std::string axis_label(const std::string& label, const std::string& unit) {
  return unit.empty() ? label : label + " [" + unit + "]";
}

struct Extent {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  std::vector<double> ticks(int target) const {
    std::vector<double> t = lo <= hi ? nice_ticks(lo, hi, target) : std::vector<double>{};
    return t.empty() ? nice_ticks(0, 1, target) : t;
  }
};

// Data to pixels for one panel's plot area.
struct Mapping {
  double x_lo, x_hi, y_lo, y_hi, left, top, width, height;
  bool pixel(double x, double y, double& px, double& py) const {
    px = left + (x - x_lo) / (x_hi - x_lo) * width;
    py = top + (y_hi - y) / (y_hi - y_lo) * height;
    return std::isfinite(px) && std::isfinite(py);
  }
};

inline std::string point(double px, double py) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.2f,%.2f ", px, py);
  return buffer;
}

}  // namespace detail

inline std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {};
  if (lo > hi) std::swap(lo, hi);
  const double magnitude = std::max(std::abs(lo), std::abs(hi));
  if (hi - lo <= 1e-12 * magnitude) {
    const double half = lo != 0 ? 0.1 * std::abs(lo) : 1.0;
    hi = lo + half;
    lo -= half;
  }
  const double width = hi - lo;
  target = std::clamp(target, 3, 20);
  const double raw = width / target;
  if (!std::isfinite(raw) || raw < 1e-300 || raw > 1e300) return {};
  // Candidates m * 10^e around raw; keep the one whose outer ticks span the
  // least (the tightest axis) among those giving 3 .. target + 2 ticks.
  const int raw_exponent = static_cast<int>(std::floor(std::log10(raw)));
  int mantissa = 0, exponent = 0;
  double best_span = std::numeric_limits<double>::infinity();
  for (int e = raw_exponent - 1; e <= raw_exponent + 1; ++e) {
    for (int m : {1, 2, 5}) {
      const double candidate = m * std::pow(10.0, e);
      const double span = candidate * (std::ceil(hi / candidate) - std::floor(lo / candidate));
      const double count = span / candidate + 1;
      if (count >= 3 && count <= target + 2 && span < best_span) {
        best_span = span;
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
    const double tick = detail::parse_decimal(k * mantissa, exponent);
    if (!std::isfinite(tick)) return {};
    ticks.push_back(tick);
  }
  while (ticks.size() > 2 && ticks[1] <= lo)
    ticks.erase(ticks.begin());
  while (ticks.size() > 2 && ticks[ticks.size() - 2] >= hi)
    ticks.pop_back();
  return ticks;
}

inline std::string render_svg(const Figure& figure) {
  using detail::escape;
  const double left = 80, legend_width = 160, header = figure.subtitle.empty() ? 40 : 62;
  const double plot_width = std::max(figure.width - left - legend_width, 100.0);
  const double plot_height = std::max(figure.panel_height - 80, 40.0);
  const double height = header + figure.panels.size() * figure.panel_height + 8;
  char buffer[512];
  std::snprintf(buffer, sizeof buffer,
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg "
                "xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"13\">\n"
                "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
                figure.width, height, figure.width, height);
  std::string svg = buffer;
  svg += "<text x=\"16\" y=\"26\" font-size=\"17\" font-weight=\"bold\">" + escape(figure.title) +
         "</text>\n";
  if (!figure.subtitle.empty()) {
    svg += "<text x=\"16\" y=\"48\" fill=\"#444\">" + escape(figure.subtitle) + "</text>\n";
  }
  for (std::size_t p = 0; p < figure.panels.size(); ++p) {
    const Panel& panel = figure.panels[p];
    const double panel_top = header + p * figure.panel_height;
    const double top = panel_top + 30, bottom = top + plot_height, right = left + plot_width;
    detail::Extent x_extent, y_extent;
    for (const Band& band : panel.bands) {
      for (double v : band.x)
        x_extent.add(v);
      for (double v : band.lower)
        y_extent.add(v);
      for (double v : band.upper)
        y_extent.add(v);
    }
    for (const Series& series : panel.series) {
      for (double v : series.x)
        x_extent.add(v);
      for (double v : series.y)
        y_extent.add(v);
    }
    const std::vector<double> x_ticks = x_extent.ticks(6), y_ticks = y_extent.ticks(5);
    const detail::Mapping map{x_ticks.front(), x_ticks.back(), y_ticks.front(),
                              y_ticks.back(),  left,           top,
                              plot_width,      plot_height};
    svg += "<text x=\"" + std::to_string(int(left)) + "\" y=\"" + std::to_string(int(top - 10)) +
           "\" font-size=\"14\" font-weight=\"bold\">" + escape(panel.title) + "</text>\n";
    // Grid and tick labels: the axis spans exactly the outer ticks.
    const std::vector<std::string> x_labels = detail::format_ticks(x_ticks);
    const std::vector<std::string> y_labels = detail::format_ticks(y_ticks);
    for (std::size_t k = 0; k < x_ticks.size(); ++k) {
      double px = 0, py = 0;
      map.pixel(x_ticks[k], y_ticks.front(), px, py);
      std::snprintf(buffer, sizeof buffer,
                    "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"#e4e4e4\"/>\n"
                    "<text class=\"tick x\" x=\"%.2f\" y=\"%.2f\" font-size=\"12\" "
                    "text-anchor=\"middle\">%s</text>\n",
                    px, top, px, bottom, px, bottom + 16, x_labels[k].c_str());
      svg += buffer;
    }
    for (std::size_t k = 0; k < y_ticks.size(); ++k) {
      double px = 0, py = 0;
      map.pixel(x_ticks.front(), y_ticks[k], px, py);
      std::snprintf(buffer, sizeof buffer,
                    "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"#e4e4e4\"/>\n"
                    "<text class=\"tick y\" x=\"%.2f\" y=\"%.2f\" font-size=\"12\" "
                    "text-anchor=\"end\">%s</text>\n",
                    left, py, right, py, left - 6, py + 4, y_labels[k].c_str());
      svg += buffer;
    }
    std::snprintf(buffer, sizeof buffer,
                  "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"none\" "
                  "stroke=\"#888\"/>\n<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\">",
                  left, top, plot_width, plot_height, left + plot_width / 2, bottom + 36);
    svg += buffer + escape(detail::axis_label(panel.x_label, panel.x_unit)) + "</text>\n";
    std::snprintf(buffer, sizeof buffer,
                  "<text x=\"20\" y=\"%.2f\" transform=\"rotate(-90 20 %.2f)\" "
                  "text-anchor=\"middle\">",
                  top + plot_height / 2, top + plot_height / 2);
    svg += buffer + escape(detail::axis_label(panel.y_label, panel.y_unit)) + "</text>\n";

    // Bands under the series; each finite run of points is one polygon.
    for (const Band& band : panel.bands) {
      const std::size_t n = std::min({band.x.size(), band.lower.size(), band.upper.size()});
      std::size_t i = 0;
      while (i < n) {
        std::vector<std::pair<double, double>> upper, lower;
        for (; i < n; ++i) {
          double px = 0, upper_y = 0, lower_y = 0;
          if (!map.pixel(band.x[i], band.upper[i], px, upper_y) ||
              !map.pixel(band.x[i], band.lower[i], px, lower_y)) {
            ++i;
            break;
          }
          upper.emplace_back(px, upper_y);
          lower.emplace_back(px, lower_y);
        }
        if (upper.size() < 2) continue;
        std::string points;
        for (const auto& [px, py] : upper)
          points += detail::point(px, py);
        for (auto it = lower.rbegin(); it != lower.rend(); ++it) {
          points += detail::point(it->first, it->second);
        }
        svg += "<polygon points=\"" + points + "\" fill=\"" + escape(band.colour) +
               "\" fill-opacity=\"0.22\" stroke=\"none\"/>\n";
      }
    }
    for (const Series& series : panel.series) {
      const std::size_t n = std::min(series.x.size(), series.y.size());
      const std::string colour = escape(series.colour);
      std::string points;
      for (std::size_t i = 0; i <= n; ++i) {
        double px = 0, py = 0;
        const bool finite = i < n && map.pixel(series.x[i], series.y[i], px, py);
        if (finite && series.points) {
          std::snprintf(buffer, sizeof buffer, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.3\" fill=\"",
                        px, py);
          svg += buffer + colour + "\"/>\n";
        } else if (finite) {
          points += detail::point(px, py);
        } else if (!points.empty()) {  // a gap or the end: close this run
          svg += "<polyline points=\"" + points + "\" fill=\"none\" stroke=\"" + colour +
                 "\" stroke-width=\"1.8\"" + (series.dashed ? " stroke-dasharray=\"6 4\"" : "") +
                 "/>\n";
          points.clear();
        }
      }
    }

    // Legend, right of the plot: one row per series and band.
    double row = top + 12;
    const double swatch = right + 14, text_x = right + 40;
    for (const Series& series : panel.series) {
      const std::string colour = escape(series.colour);
      if (series.points) {
        std::snprintf(buffer, sizeof buffer, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"3\" fill=\"",
                      swatch + 10, row - 4);
      } else {
        std::snprintf(
            buffer, sizeof buffer,
            "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke-width=\"1.8\"%s "
            "stroke=\"",
            swatch, row - 4, swatch + 20, row - 4,
            series.dashed ? " stroke-dasharray=\"6 4\"" : "");
      }
      svg += buffer + colour + "\"/>\n";
      std::snprintf(buffer, sizeof buffer, "<text x=\"%.2f\" y=\"%.2f\" font-size=\"12\">", text_x,
                    row);
      svg += buffer + escape(series.label) + "</text>\n";
      row += 18;
    }
    for (const Band& band : panel.bands) {
      std::snprintf(buffer, sizeof buffer,
                    "<rect x=\"%.2f\" y=\"%.2f\" width=\"20\" height=\"10\" fill-opacity=\"0.22\" "
                    "fill=\"",
                    swatch, row - 9);
      svg += buffer + escape(band.colour) + "\"/>\n";
      std::snprintf(buffer, sizeof buffer, "<text x=\"%.2f\" y=\"%.2f\" font-size=\"12\">", text_x,
                    row);
      svg += buffer + escape(band.label) + "</text>\n";
      row += 18;
    }
  }
  return svg + "</svg>\n";
}

}  // namespace bireg_plot
