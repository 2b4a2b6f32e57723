#include "dwellfit/estimator/studies/study_pages.h"

#include <cmath>

#include "boost/algorithm/string/join.hpp"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/run/html_report.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

std::string Score(double hz, double percent) {
  return std::isnan(percent) ? "-" : StringPrintf("%.3g Hz (%.3g %%)", hz, percent);
}

}  // namespace

std::string ModelSelectionToHtml(const ModelSelectionReport& report, const std::string& markdown) {
  const bool chosen = report.recommended >= 0;
  std::string body =
      "<p>Config: <code>" + HtmlEscape(report.config_path) + "</code></p>\n" +
      StringPrintf("<div class=\"status %s\" id=\"status\"><b>%s</b>: ", chosen ? "ok" : "bad",
                   chosen ? "recommended" : "no variant qualifies") +
      HtmlEscape(chosen ? report.variants[report.recommended].variant.Name() + ". " : "") +
      HtmlEscape(report.verdict) + "</div>\n<p>Rule: " + HtmlEscape(report.rule) + "</p>\n";
  body += "<h2>Warnings</h2>\n<ul id=\"warnings\">\n";
  for (const std::string& warning : report.warnings)
    body += "<li>" + HtmlEscape(warning) + "</li>\n";
  if (report.warnings.empty()) body += "<li>none</li>\n";
  std::vector<std::vector<std::string>> rows;
  for (const VariantResult& v : report.variants) {
    rows.push_back(
        {v.variant.Name(), std::to_string(v.free_parameters), v.eligible ? "yes" : "no",
         Score(v.jump_down_hz, v.jump_down_percent), Score(v.jump_up_hz, v.jump_up_percent),
         std::isnan(v.upper_branch_percent) ? "-" : StringPrintf("%.3g %%", v.upper_branch_percent),
         StringPrintf("%.6g", v.aic), StringPrintf("%.6g", v.bic),
         v.unstable ? v.stability : "stable"});
  }
  body += "</ul>\n<h2>Variants: median held-out errors</h2>\n" +
          HtmlTable("variants",
                    {"variant", "free parameters", "every fit converged", "jump-down", "jump-up",
                     "upper-branch amplitude", "AIC", "BIC", "stability"},
                    rows) +
          "<h2>The whole report</h2>\n<pre id=\"markdown\">" + HtmlEscape(markdown) + "</pre>\n";
  return HtmlPage("dwellfit select_model: " + report.config_path, body);
}

std::string StudyToHtml(const SensitivityStudy& study, const std::vector<NamedFile>& files) {
  std::string body = StringPrintf(
      "<p>%d fits: %d cases of %d replicas; varied: %s.</p>\n", study.total_fits, study.cases,
      study.replicas,
      study.axis_keys.empty() ? "nothing"
                              : HtmlEscape(boost::algorithm::join(study.axis_keys, ", ")).c_str());
  std::vector<std::vector<std::string>> rows;
  for (const NamedFile& file : files) {
    if (file.first != "summary.yaml") continue;
    for (const YAML::Node& c : YAML::Load(file.second)["cases"]) {
      std::string settings;
      for (const auto& setting : c["settings"]) {
        settings +=
            setting.first.as<std::string>() + " = " + setting.second.as<std::string>() + " ";
      }
      for (const auto& parameter : c["parameters"]) {
        const YAML::Node& p = parameter.second;
        rows.push_back({c["case"].as<std::string>(), settings,
                        c["usable"].as<std::string>() + " of " + c["fits"].as<std::string>(),
                        parameter.first.as<std::string>(), p["mean"].as<std::string>(),
                        p["std"].as<std::string>(), p["mean_se"].as<std::string>(),
                        p["bias"] ? p["bias"].as<std::string>() : "-"});
      }
    }
  }
  body += "<h2>Estimates per case, over the usable fits</h2>\n" +
          HtmlTable("summary",
                    {"case", "settings", "usable fits", "parameter", "mean", "std",
                     "mean standard error", "bias"},
                    rows) +
          "<h2>Figures</h2>\n" + InlineSvgFigures(files, "profile");
  return HtmlPage("dwellfit sensitivity study", body);
}

}  // namespace dwellfit
