#include "nrslam/batch/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace nrslam {
namespace {

// Tick spacing of 1, 2 or 5 × 10^k giving about `count` ticks over `range`.
double NiceStep(double range, int count) {
  const double raw = range / std::max(1, count);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double factor : {1.0, 2.0, 5.0, 10.0}) {
    if (factor * magnitude >= raw) return factor * magnitude;
  }
  return 10.0 * magnitude;
}

std::string Number(double value) {
  std::ostringstream text;
  text << (std::abs(value) < 1e-12 ? 0.0 : value);
  return text.str();
}

}  // namespace

std::string EscapeXml(const std::string& text) {
  std::string escaped;
  for (char c : text) {
    if (c == '<') escaped += "&lt;";
    else if (c == '>') escaped += "&gt;";
    else if (c == '&') escaped += "&amp;";
    else if (c == '"') escaped += "&quot;";
    else escaped += c;
  }
  return escaped;
}

std::string LinePlotSvg(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min, y_min = x_min, y_max = -x_min;
  for (const PlotSeries& s : series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x_min = std::min(x_min, s.x[i]);
      x_max = std::max(x_max, s.x[i]);
      y_min = std::min(y_min, s.y[i]);
      y_max = std::max(y_max, s.y[i]);
    }
  }
  if (!std::isfinite(x_min)) x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  if (!options.equal_aspect) y_min = std::min(y_min, 0.0);  // error plots start at zero
  if (x_max - x_min < 1e-9) x_max = x_min + 1;
  if (y_max - y_min < 1e-9) y_max = y_min + 1;
  const double left = 56, right = 12, bottom = 40;
  const double plot_w = options.width - left - right;
  // The legend (series with a name) flows in rows under the title, as many as it needs: a
  // sweep plots one series per sequence.
  struct LegendEntry {
    const PlotSeries* series;
    double x;
    int row;
  };
  std::vector<LegendEntry> legend;
  double legend_x = left;
  int legend_row = 0;
  for (const PlotSeries& s : series) {
    if (s.name.empty()) continue;
    const double entry_width = 20 + 7 * static_cast<double>(s.name.size()) + 12;
    if (legend_x > left && legend_x + entry_width > left + plot_w) {
      legend_x = left;
      ++legend_row;
    }
    legend.push_back({&s, legend_x, legend_row});
    legend_x += entry_width;
  }
  const double top = 28 + (legend.empty() ? 0 : 14 * (legend_row + 1));
  const double plot_h = options.height - top - bottom;
  if (options.equal_aspect) {  // grow the smaller range so one unit is as long on both axes
    const double scale = std::max((x_max - x_min) / plot_w, (y_max - y_min) / plot_h);
    const double cx = 0.5 * (x_min + x_max), cy = 0.5 * (y_min + y_max);
    x_min = cx - 0.5 * scale * plot_w, x_max = cx + 0.5 * scale * plot_w;
    y_min = cy - 0.5 * scale * plot_h, y_max = cy + 0.5 * scale * plot_h;
  } else {
    y_max += 0.05 * (y_max - y_min);
  }
  auto px = [&](double x) { return left + (x - x_min) / (x_max - x_min) * plot_w; };
  auto py = [&](double y) { return top + plot_h - (y - y_min) / (y_max - y_min) * plot_h; };

  std::ostringstream svg;
  svg << "<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" width=\"" << options.width << "\" height=\""
      << options.height << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  svg << "<text x=\"" << left << "\" y=\"16\" font-size=\"13\" font-weight=\"bold\">" << EscapeXml(options.title)
      << "</text>\n";
  svg << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << plot_w << "\" height=\"" << plot_h
      << "\" fill=\"none\" stroke=\"#888\"/>\n";
  const double x_step = NiceStep(x_max - x_min, 6), y_step = NiceStep(y_max - y_min, 5);
  for (double x = std::ceil(x_min / x_step) * x_step; x <= x_max + 1e-9; x += x_step) {
    svg << "<line x1=\"" << px(x) << "\" y1=\"" << top << "\" x2=\"" << px(x) << "\" y2=\"" << top + plot_h
        << "\" stroke=\"#eee\"/><text x=\"" << px(x) << "\" y=\"" << top + plot_h + 14
        << "\" text-anchor=\"middle\">" << Number(x) << "</text>\n";
  }
  for (double y = std::ceil(y_min / y_step) * y_step; y <= y_max + 1e-9; y += y_step) {
    svg << "<line x1=\"" << left << "\" y1=\"" << py(y) << "\" x2=\"" << left + plot_w << "\" y2=\"" << py(y)
        << "\" stroke=\"#eee\"/><text x=\"" << left - 4 << "\" y=\"" << py(y) + 4 << "\" text-anchor=\"end\">"
        << Number(y) << "</text>\n";
  }
  svg << "<text x=\"" << left + plot_w / 2 << "\" y=\"" << options.height - 6 << "\" text-anchor=\"middle\">"
      << EscapeXml(options.x_label) << "</text>\n";
  svg << "<text transform=\"translate(14," << top + plot_h / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
      << EscapeXml(options.y_label) << "</text>\n";
  for (const LegendEntry& entry : legend) {
    const double y = 30 + 14 * entry.row;
    svg << "<line x1=\"" << entry.x << "\" y1=\"" << y - 4 << "\" x2=\"" << entry.x + 16 << "\" y2=\"" << y - 4
        << "\" stroke=\"" << entry.series->colour << "\" stroke-width=\"2\"/><text x=\"" << entry.x + 20 << "\" y=\"" << y
        << "\">" << EscapeXml(entry.series->name) << "</text>\n";
  }
  for (const PlotSeries& s : series) {
    std::ostringstream points;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      points << px(s.x[i]) << ',' << py(s.y[i]) << ' ';
      if (s.markers) {
        svg << "<circle cx=\"" << px(s.x[i]) << "\" cy=\"" << py(s.y[i]) << "\" r=\"3\" fill=\"" << s.colour << "\"/>\n";
      }
    }
    svg << "<polyline class=\"series\" fill=\"none\" stroke=\"" << s.colour << "\" stroke-width=\"1.5\" points=\""
        << points.str() << "\"/>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace nrslam
