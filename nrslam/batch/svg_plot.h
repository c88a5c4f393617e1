// batch: small self-contained SVG line plots for the HTML report (no scripts, no fonts to
// load), so a report opens anywhere, offline, and can be archived as is.
#pragma once

#include <string>
#include <vector>

namespace nrslam {

struct PlotSeries {
  std::string name;
  std::string colour;  // CSS colour
  std::vector<double> x, y;
  bool markers = false;  // a dot per point (for sparse data, e.g. a sweep)
};

struct PlotOptions {
  std::string title, x_label, y_label;
  int width = 520, height = 300;  // px
  bool equal_aspect = false;      // same scale on both axes (trajectories)
};

// Text made safe inside HTML/SVG elements and attribute values.
std::string EscapeXml(const std::string& text);

// An <svg> element (class "plot") with axes, ticks, the series and a legend of the series
// that have a name.
std::string LinePlotSvg(const std::vector<PlotSeries>& series, const PlotOptions& options);

}  // namespace nrslam
