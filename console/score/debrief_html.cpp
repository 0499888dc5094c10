// The debrief page, written as text: SVG polylines for the plots, SVG rectangles for the heat map.
#include "console/score/debrief_html.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace resecto {
namespace {

std::string format(const char* pattern, double v) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, v);
  return text;
}

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// A metric's row: name, unit, how to print it, and the reference figure (labelled with its source).
struct MetricRow {
  const char* label;
  const char* unit;
  std::function<std::string(const ScoreMetrics&)> value;
  const char* reference;
};

/// A lobe as a reader writes it: "left lateral", not the report's key "left_lateral".
std::string lobe_display_name(int lobe) {
  std::string name = kLobeNames[lobe];
  std::replace(name.begin(), name.end(), '_', ' ');
  return name;
}

std::string number(double v, int decimals) {
  char pattern[8];
  std::snprintf(pattern, sizeof pattern, "%%.%df", decimals);
  return format(pattern, v);
}

std::vector<MetricRow> metric_rows() {
  auto real = [](double ScoreMetrics::*field, int decimals) {
    return [field, decimals](const ScoreMetrics& m) { return number(m.*field, decimals); };
  };
  auto count = [](std::uint64_t ScoreMetrics::*field) {
    return [field](const ScoreMetrics& m) { return std::to_string(m.*field); };
  };
  return {
      {"Procedure time", "s", real(&ScoreMetrics::procedure_time_s, 1),
       "K\u00e4llstr\u00f6m 2010 (PelvicVision, full TURP): urologists took half the students' time for the same resected volume"},
      {"Resected, total", "g", real(&ScoreMetrics::resected_total_g, 2),
       "Sweet 2004: experts resected more grams than novices (direction reported; the figures depend on the gland)"},
      {"Resected from the adenoma", "g", real(&ScoreMetrics::resected_adenoma_g, 2), ""},
      {"Resected from the capsule", "g", real(&ScoreMetrics::resected_capsule_g, 2), "Target 0 (capsule is not adenoma)"},
      {"Adenoma remaining", "fraction", real(&ScoreMetrics::remaining_adenoma_fraction, 3),
       "UroSim pass mark: at least 85% resected, i.e. at most 0.15 remaining (Soomro: faculty resection score 112 \u00b1 8.6 of 120, residents' first attempt 86.7 \u00b1 10.0)"},
      {"Resection rate", "g/min", real(&ScoreMetrics::grams_per_minute, 2), "Bright 2012 (TURPsim, median lobe): experts resected a greater percentage per minute than novices (p < 0.01)"},
      {"Grams per cut", "g",
       [](const ScoreMetrics& m) { return has_grams_per_cut(m) ? number(m.grams_per_cut, 3) : std::string("n/a (no cut)"); },
       "Sweet 2004 (UW trainer): experts resected more grams per cut (p = 0.002)"},
      {"Cuts", "strokes", count(&ScoreMetrics::cuts), ""},
      {"Chips", "", count(&ScoreMetrics::chips), ""},
      {"Capsular perforations", "strokes", count(&ScoreMetrics::perforations), "Sweet 2004 counts them as errors; target 0"},
      {"Sphincter-zone violations", "strokes", count(&ScoreMetrics::sphincter_zone_violations),
       "Cuts distal to the verumontanum; Sweet 2004 error; target 0"},
      {"Sphincter-zone cutting", "s", real(&ScoreMetrics::sphincter_zone_cut_s, 2), "Target 0"},
      // The metric is the pedal down with nothing cut (the loop out in fluid, or retracted against the
      // beak while the sheath presses tissue), the simulator's measure of Bright's idle diathermy.
      {"Cutting pedal down, nothing cut", "s", real(&ScoreMetrics::loop_on_idle_s, 2),
       "Bright 2012 (TURPsim): experts less active diathermy time without contact than novices (p < 0.01)"},
      {"Tool path (the loop wire's middle)", "mm", real(&ScoreMetrics::tool_path_mm, 0), "K\u00e4llstr\u00f6m 2010: students' resectoscope-tip path longer than urologists'"},
      {"Tool-tip mean speed", "mm/s", real(&ScoreMetrics::tool_mean_speed_mm_s, 1), ""},
      {"Time in contact", "s", real(&ScoreMetrics::contact_time_s, 2), ""},
      {"Peak reaction force", "N", real(&ScoreMetrics::peak_force_n, 3), ""},
      {"Mean contact force", "N", real(&ScoreMetrics::mean_contact_force_n, 3), ""},
      {"Lobe order", "", [](const ScoreMetrics& m) {
         std::string text;
         for (std::size_t i = 0; i < m.lobe_order.size(); ++i) text += (i ? " &rarr; " : "") + lobe_display_name(m.lobe_order[i]);
         return text.empty() ? std::string("none resected") : text;
       }, "Standard order: median lobe first, then the lateral lobes"},
      {"Blood loss per gram", "ml/g", [](const ScoreMetrics&) { return std::string("unavailable (no bleeding model yet)"); },
       "Sweet 2004: experts less blood loss per gram resected (p = 0.032)"},
      {"Irrigant per gram", "l/g", [](const ScoreMetrics&) { return std::string("unavailable (no irrigation model yet)"); },
       "K\u00e4llstr\u00f6m 2010: students used about 5 times the urologists' irrigant per resected volume; Sweet 2004: p = 0.02"},
  };
}

/// A time plot: `value` of every sample (a min/max envelope per pixel column when there are more
/// samples than columns), axes labelled with the range.
/// `min_span`: the least range the vertical axis shows, in the plot's unit, so a trace that barely
/// moves (a still hand's sensor noise, 0.1 mm) is drawn flat rather than stretched to the full height.
std::string plot_svg(const std::vector<ScoreSample>& series, const char* title, const char* unit, const char* colour, double min_span,
                     const std::function<double(const ScoreSample&)>& value) {
  constexpr int kWidth = 460, kHeight = 130, kLeft = 48, kBottom = 20, kTop = 18;
  const int plot_w = kWidth - kLeft - 8, plot_h = kHeight - kTop - kBottom;
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(kWidth) + "\" height=\"" + std::to_string(kHeight) +
                    "\" class=\"plot\"><text x=\"4\" y=\"13\" class=\"title\">" + title + " (" + unit + ")</text>";
  if (series.empty()) return svg + "<text x=\"60\" y=\"60\">no samples</text></svg>";
  double lo = value(series.front()), hi = lo;
  for (const ScoreSample& s : series) lo = std::min(lo, value(s)), hi = std::max(hi, value(s));
  if (hi - lo < min_span) {
    // Centred on the trace, but a quantity that is never negative keeps its axis from zero up.
    const double middle = 0.5 * (lo + hi);
    lo = lo >= 0.0 ? std::max(0.0, middle - 0.5 * min_span) : middle - 0.5 * min_span;
    hi = lo + min_span;
  }
  if (hi - lo < 1e-12) hi = lo + 1.0;
  const double t0 = series.front().time_s, t1 = std::max(series.back().time_s, t0 + 1e-9);
  auto px = [&](double t) { return kLeft + (t - t0) / (t1 - t0) * plot_w; };
  auto py = [&](double v) { return kTop + (1.0 - (v - lo) / (hi - lo)) * plot_h; };
  svg += "<rect x=\"" + std::to_string(kLeft) + "\" y=\"" + std::to_string(kTop) + "\" width=\"" + std::to_string(plot_w) + "\" height=\"" +
         std::to_string(plot_h) + "\" fill=\"#fafafa\" stroke=\"#999\"/>";
  // Per column: the first sample's value, then the column's min and max, so spikes survive.
  std::string points;
  std::size_t i = 0;
  for (int column = 0; column < plot_w && i < series.size(); ++column) {
    const double column_end = t0 + (column + 1.0) / plot_w * (t1 - t0);
    double cmin = value(series[i]), cmax = cmin;
    const double first = cmin;
    while (i < series.size() && series[i].time_s <= column_end) cmin = std::min(cmin, value(series[i])), cmax = std::max(cmax, value(series[i])), ++i;
    const double x = px(std::min(column_end, t1));
    points += format("%.1f,", x) + format("%.1f ", py(first)) + format("%.1f,", x) + format("%.1f ", py(cmax)) + format("%.1f,", x) +
              format("%.1f ", py(cmin));
  }
  svg += "<polyline fill=\"none\" stroke=\"" + std::string(colour) + "\" stroke-width=\"1.2\" points=\"" + points + "\"/>";
  svg += "<text x=\"2\" y=\"" + std::to_string(kTop + 8) + "\" class=\"axis\">" + number(hi, 2) + "</text>";
  svg += "<text x=\"2\" y=\"" + std::to_string(kTop + plot_h) + "\" class=\"axis\">" + number(lo, 2) + "</text>";
  svg += "<text x=\"" + std::to_string(kLeft) + "\" y=\"" + std::to_string(kHeight - 4) + "\" class=\"axis\">" + number(t0, 1) + " s</text>";
  svg += "<text x=\"" + std::to_string(kWidth - 60) + "\" y=\"" + std::to_string(kHeight - 4) + "\" class=\"axis\">" + number(t1, 1) + " s</text>";
  return svg + "</svg>";
}

std::string section_for(const RecordingScore& s) {
  std::string html = "<section><h2>" + escape(s.file) + "</h2><p>procedure <b>" + escape(s.procedure) + "</b> on a gland of " +
                     std::to_string(s.surface_triangles) + " surface triangles, " + number(s.score.metrics.procedure_time_s, 1) + " s simulated, " +
                     std::to_string(s.verified_hashes) + " collision steps re-simulated and verified against the recording</p>";
  if (!s.interrupted.empty()) {
    html += "<p class=\"warn\">The run was interrupted by " + escape(s.interrupted) + ": scored as far as it went, not as a finished procedure.</p>";
  }
  html += "<h3>Plots over time</h3>";
  const std::vector<ScoreSample>& series = s.score.series;
  html += plot_svg(series, "Reaction force, largest of each step", "N", "#1d3557", 1.0, [](const ScoreSample& x) { return x.force_n; });
  html += plot_svg(series, "Cutting pedal", "down = 1", "#d62828", 1.0, [](const ScoreSample& x) { return x.cutting ? 1.0 : 0.0; });
  html += plot_svg(series, "Insertion depth past the apex", "mm", "#2a9d8f", 10.0, [](const ScoreSample& x) { return x.insertion_mm; });
  html += plot_svg(series, "Resected tissue", "g", "#e76f51", 0.1, [](const ScoreSample& x) { return x.resected_g; });
  html += "<h3>Resection heat map</h3><p class=\"legend\"><span style=\"background:" + std::string(kRemovedAdenomaColour) +
          "\"></span>removed adenoma <span style=\"background:" + kRemainingAdenomaColour + "\"></span>remaining adenoma <span style=\"background:" +
          kRemovedCapsuleColour + "\"></span>removed capsule <span style=\"background:" + kRemainingCapsuleColour +
          "\"></span>capsule<br>Slabs along the urethra by the tissue's rest position, z from the apex; a cell is removed when the loop "
          "cut it or it left with a chip the cuts freed.</p>" +
          heat_map_svg(s.score.heat_map);
  return html + "</section>";
}

}  // namespace

std::string heat_map_svg(const ResectionHeatMap& map) {
  constexpr int kCellPx = 7, kGap = 14;
  const int slice_w = map.nx * kCellPx, slice_h = map.ny * kCellPx;
  const int width = std::max(1, map.nz * (slice_w + kGap)), height = slice_h + 34;
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"heatmap\" width=\"" + std::to_string(width) + "\" height=\"" +
                    std::to_string(height) + "\">";
  const double cell_m3 = map.cell.x * map.cell.y * map.cell.z;
  for (int k = 0; k < map.nz; ++k) {
    const int x0 = k * (slice_w + kGap);
    // The slab's extent, not its centre: a cut a few millimetres proximal of the verumontanum lands in
    // the apex's slab, which its centre alone made read as apical resection (audit 11).
    const double from_mm = (map.origin.z + k * map.cell.z) * 1000.0, to_mm = (map.origin.z + (k + 1) * map.cell.z) * 1000.0;
    svg += "<text x=\"" + std::to_string(x0) + "\" y=\"" + std::to_string(slice_h + 14) + "\" class=\"axis\">z " + number(from_mm, 1) +
           " to " + number(to_mm, 1) + " mm" + (k == 0 ? " (apex)" : k == map.nz - 1 ? " (bladder neck)" : "") + "</text>";
    for (int j = 0; j < map.ny; ++j) {
      for (int i = 0; i < map.nx; ++i) {
        const std::size_t c = (static_cast<std::size_t>(k) * static_cast<std::size_t>(map.ny) + static_cast<std::size_t>(j)) * static_cast<std::size_t>(map.nx) +
                              static_cast<std::size_t>(i);
        const double adenoma = map.initial_adenoma_m3[c], capsule = map.initial_capsule_m3[c];
        if (adenoma + capsule < 0.05 * cell_m3) continue;  // the channel and outside the gland
        const char* colour = adenoma >= capsule ? kRemainingAdenomaColour : kRemainingCapsuleColour;
        if (map.removed_capsule_m3[c] >= 0.2 * (adenoma + capsule)) {
          colour = kRemovedCapsuleColour;
        } else if (map.removed_adenoma_m3[c] >= 0.3 * adenoma && adenoma > 0.0) {
          colour = kRemovedAdenomaColour;
        }
        // Patient's left (+x) drawn on the right, as seen from the apex looking up the channel; anterior up.
        const int px = x0 + i * kCellPx, py = (map.ny - 1 - j) * kCellPx;
        svg += "<rect x=\"" + std::to_string(px) + "\" y=\"" + std::to_string(py) + "\" width=\"" + std::to_string(kCellPx) + "\" height=\"" +
               std::to_string(kCellPx) + "\" fill=\"" + colour + "\"/>";
      }
    }
  }
  return svg + "</svg>";
}

std::string debrief_html(std::span<const RecordingScore> scores) {
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Resecto debrief</title><style>"
      "body{font-family:sans-serif;margin:16px;color:#222}table{border-collapse:collapse;margin-bottom:16px}"
      "td,th{border:1px solid #bbb;padding:3px 8px;font-size:13px;text-align:left}th{background:#eee}"
      ".cols{display:flex;flex-wrap:wrap;gap:24px}.cols section{flex:1 1 480px;min-width:0;overflow-x:auto}.plot{display:block;margin:4px 0}.title{font-size:12px;font-weight:bold}"
      ".axis{font-size:10px;fill:#555}.legend span{display:inline-block;width:12px;height:12px;margin:0 4px 0 12px;vertical-align:middle}"
      ".ref{color:#555;font-size:12px}.warn{color:#9d0208;font-weight:bold}</style></head><body><h1>Resecto debrief</h1>";
  html += "<h2>Metrics</h2><table><tr><th>Metric</th><th>Unit</th>";
  for (const RecordingScore& s : scores) html += "<th>" + escape(s.file) + "</th>";
  html += "<th>Reference (literature figures and targets)</th></tr>";
  for (const MetricRow& row : metric_rows()) {
    html += "<tr><td>" + std::string(row.label) + "</td><td>" + row.unit + "</td>";
    for (const RecordingScore& s : scores) html += "<td>" + row.value(s.score.metrics) + "</td>";
    html += "<td class=\"ref\">" + escape(row.reference) + "</td></tr>";
  }
  html += "</table><div class=\"cols\">";
  for (const RecordingScore& s : scores) html += section_for(s);
  return html + "</div></body></html>\n";
}

}  // namespace resecto
