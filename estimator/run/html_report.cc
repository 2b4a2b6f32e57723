#include "dwellfit/estimator/run/html_report.h"

#include <algorithm>
#include <cmath>

#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/common/version.h"
#include "dwellfit/estimator/run/run_figures.h"

namespace dwellfit {
namespace {

constexpr char kStyle[] =
    "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}"
    "table{border-collapse:collapse;margin:0.5em 0 1.5em}"
    "th,td{border:1px solid #ccc;padding:3px 8px;text-align:left;vertical-align:top}"
    "th{background:#f2f2f2}td.n{text-align:right;font-variant-numeric:tabular-nums}"
    ".status{padding:0.6em 1em;border-radius:4px;margin:1em 0}"
    ".ok{background:#e3f4e1;border:1px solid #7bbf73}.bad{background:#fbe3e1;border:1px solid "
    "#d9786f}"
    "figure{margin:1em 0}figure "
    "svg{width:100%;max-width:900px;height:auto}pre{background:#f7f7f7;padding:1em;"
    "overflow-x:auto}";

std::string Cell(const std::string& text, bool number = false) {
  return std::string(number ? "<td class=\"n\">" : "<td>") + HtmlEscape(text) + "</td>";
}

std::string Header(const std::vector<std::string>& names) {
  std::string row = "<tr>";
  for (const std::string& name : names) row += "<th>" + HtmlEscape(name) + "</th>";
  return row + "</tr>\n";
}

std::string StatusSection(const IdentificationReport& report) {
  const bool ok = report.result.status == FitStatus::kConverged;
  return StringPrintf("<div class=\"status %s\" id=\"status\"><b>%s</b>: %s</div>\n",
                      ok ? "ok" : "bad", FitStatusName(report.result.status),
                      HtmlEscape(report.result.message).c_str());
}

// The estimates with their intervals and units; omega also in Hz.
std::string EstimatesSection(const IdentificationReport& report, const DataUnits& units) {
  const ParameterUncertainty& u = report.uncertainty;
  const ModelForm form = report.options.solve.residual.form;
  std::string html = "<h2>Estimates</h2>\n<p>95 % intervals: " +
                     HtmlEscape(u.available ? u.interval_kind : "none") + ". " +
                     HtmlEscape(u.message) + "</p>\n<table id=\"estimates\">\n" +
                     Header({"parameter", "unit", "estimate", "95 % interval",
                             "linearised standard error", "note"});
  std::vector<int> held;
  if (!report.result.stages.empty()) held = report.result.stages.back().held_at_bound;
  for (int i = 0; i < kNumParameters; ++i) {
    const double value = report.result.parameters[i];
    std::string note;
    if (report.options.fixed[i]) note = "fixed";
    if (std::find(held.begin(), held.end(), i) != held.end()) note = "held at its bound";
    const bool interval = u.available && note.empty();
    html +=
        "<tr>" + Cell(ParameterName(form, i)) + Cell(ParameterUnit(form, i, units)) +
        Cell(StringPrintf("%.10g", value), true) +
        Cell(interval ? StringPrintf("[%.6g, %.6g]", u.ci95_low[i], u.ci95_high[i]) : "-", true) +
        Cell(interval ? StringPrintf("%.3g", u.standard_error[i]) : "-", true) + Cell(note) +
        "</tr>\n";
  }
  html += "</table>\n<p>" +
          HtmlEscape(StringPrintf(
              "Natural frequency %.8g Hz (omega in rad/s above). Effective nonlinearity alpha_e "
              "%.8g at %.6g rad/s, 95 %% interval [%.6g, %.6g]. Final cost %.6g.",
              RadPerSecondToHz(report.result.parameters[kNaturalFrequency]),
              u.effective_nonlinearity, u.omega_ref_rad_s, u.effective_nonlinearity_ci95_low,
              u.effective_nonlinearity_ci95_high, report.result.final_cost)) +
          "</p>\n";
  return html;
}

std::string WarningsSection(const IdentificationReport& report) {
  std::vector<std::string> warnings = report.uncertainty.warnings;
  if (!report.validation_intervals.levels.empty() &&
      !report.validation_intervals.parameter_covariance) {
    warnings.push_back(report.validation_intervals.note);
  }
  warnings.insert(warnings.end(), report.level_refits.warnings.begin(),
                  report.level_refits.warnings.end());
  std::string html = "<h2>Warnings</h2>\n<ul id=\"warnings\">\n";
  for (const std::string& warning : warnings) html += "<li>" + HtmlEscape(warning) + "</li>\n";
  if (warnings.empty()) html += "<li>none</li>\n";
  return html + "</ul>\n";
}

// Per sweep: its errors and each measured jump against the model's.
std::string SweepsSection(const IdentificationReport& report) {
  std::string html = "<h2>Fit and validation per sweep</h2>\n<table id=\"sweeps\">\n" +
                     Header({"sweep", "role", "dwells", "RMS error", "relative RMS error",
                             "past their branch's end", "jumps: measured against the model"});
  for (const SweepPrediction& p : report.predictions) {
    std::string jumps;
    for (const PredictedJump& jump : p.jumps) {
      if (!jump.measured) continue;
      jumps += (jumps.empty() ? "" : "<br>") + HtmlEscape(JumpNote(*p.sweep, jump));
    }
    html += "<tr>" + Cell(p.sweep->Name()) + Cell(p.fitted ? "fitted" : "validation") +
            Cell(std::to_string(p.sweep->points.size()), true) +
            Cell(StringPrintf("%.4g", p.rms_error), true) +
            Cell(StringPrintf("%.4g", p.relative_rms_error), true) +
            Cell(std::to_string(p.points_off_branch), true) + "<td>" +
            (jumps.empty() ? "none measured" : jumps) + "</td></tr>\n";
  }
  return html + "</table>\n";
}

std::string ValidationSection(const ValidationIntervals& v) {
  if (v.levels.empty()) return "";
  std::string html =
      "<h2>Validation: 95 % prediction intervals</h2>\n<p>" +
      HtmlEscape(std::string("Rule: ") + kPredictionIntervalRule) +
      "</p>\n<table id=\"validation\">\n" +
      Header({"sweep", "quantity", "measured", "predicted", "half-width", "error (%)", "inside"});
  for (const ValidationLevel& level : v.levels) {
    for (const HeldOutPrediction& p : level.predictions) {
      html += "<tr>" + Cell(p.sweep) + Cell(HeldOutQuantityName(p.quantity)) +
              Cell(StringPrintf("%.6g", p.measured), true) +
              Cell(StringPrintf("%.6g", p.predicted), true) +
              Cell(StringPrintf("%.3g", p.half_width), true) +
              Cell(StringPrintf("%+.2f", p.ErrorPercent()), true) + Cell(p.inside ? "yes" : "no") +
              "</tr>\n";
    }
  }
  html += "</table>\n<p>Inside their interval: ";
  const std::pair<const char*, const IntervalCoverage*> quantities[] = {
      {"jump-down", &v.coverage.jump_down},
      {"jump-up", &v.coverage.jump_up},
      {"upper-branch amplitude", &v.coverage.upper_branch}};
  for (const auto& [name, c] : quantities) {
    html += StringPrintf("%s %d of %d; ", name, c->inside, c->total);
  }
  return html + "</p>\n";
}

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
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
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string HtmlPage(const std::string& title, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         HtmlEscape(title) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n<h1>" +
         HtmlEscape(title) + "</h1>\n" + body + "<p>dwellfit " + HtmlEscape(DwellfitVersion()) +
         "</p>\n</body>\n</html>\n";
}

std::string HtmlTable(const std::string& id, const std::vector<std::string>& header,
                      const std::vector<std::vector<std::string>>& rows) {
  std::string html = "<table id=\"" + HtmlEscape(id) + "\">\n" + Header(header);
  for (const std::vector<std::string>& row : rows) {
    html += "<tr>";
    for (const std::string& cell : row) html += Cell(cell);
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

std::string InlineSvgFigures(const std::vector<NamedFile>& files, const std::string& first_stem) {
  std::vector<const NamedFile*> svgs;
  for (const NamedFile& file : files) {
    const std::string& name = file.first;
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".svg") == 0 &&
        file.second.find("<svg") != std::string::npos) {
      svgs.push_back(&file);
    }
  }
  std::stable_partition(svgs.begin(), svgs.end(), [&](const NamedFile* file) {
    return !first_stem.empty() && file->first.rfind(first_stem, 0) == 0;
  });
  std::string html;
  for (const NamedFile* file : svgs) {
    html += "<figure>\n" + file->second.substr(file->second.find("<svg")) + "<figcaption>" +
            HtmlEscape(file->first) + "</figcaption>\n</figure>\n";
  }
  return html;
}

std::string ParameterUnit(ModelForm form, int index, const DataUnits& units) {
  const std::string a = units.a.empty() ? "[A]" : units.a;
  const std::string b = units.a_base.empty() ? "[B]" : units.a_base;
  if (index == kMu3 && form.cubic_damping()) return "1/(" + a + "^2 s)";
  if (index == kAlpha5 && form.quintic_stiffness()) return "1/(" + a + "^4 s^2)";
  switch (index) {
    case kEtaE:
      return a + "/(" + b + " s^2)";
    case kMu1:
      return "1/s";
    case kMu2:
      return "1/(" + a + " s)";
    case kDelta:
      return "1/" + a + "^2";
    case kAlpha:
      return "1/(" + a + "^2 s^2)";
    default:
      return "rad/s";
  }
}

std::string ReportToHtml(const IdentificationReport& report, const std::vector<NamedFile>& figures,
                         const std::string& figures_note, const DataUnits& units) {
  std::vector<NamedFile> overview, others;
  for (const NamedFile& file : figures) {
    (file.first.rfind(kOverviewFigureStem, 0) == 0 ? overview : others).push_back(file);
  }
  const std::string overview_html = InlineSvgFigures(overview);
  std::string body = "<p>Config: <code>" + HtmlEscape(report.config_path) + "</code></p>\n";
  // The chapter's model goes unsaid, so that its pages keep their text.
  if (report.options.solve.residual.form.second_order()) {
    body += "<p>Model: second-order averaging (harmonic balance on harmonics 1 and 3)</p>\n";
  }
  body += StatusSection(report) + EstimatesSection(report, units);
  if (!overview_html.empty()) body += "<h2>Where the sweeps jump</h2>\n" + overview_html;
  body += WarningsSection(report) + SweepsSection(report) +
          ValidationSection(report.validation_intervals) + "<h2>Figures</h2>\n";
  if (!figures_note.empty()) body += "<p>" + HtmlEscape("No figures: " + figures_note) + "</p>\n";
  body += InlineSvgFigures(others) + "<h2>Configuration in effect</h2>\n<pre id=\"config\">" +
          HtmlEscape(report.config_in_effect) + "</pre>\n";
  return HtmlPage("dwellfit identify: " + report.config_path, body);
}

}  // namespace dwellfit
