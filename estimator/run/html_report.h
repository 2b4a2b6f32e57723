// report.html: one self-contained page of an identify run to read and pass
// on: the status and its reason, the estimates with their 95 % intervals and
// the intervals' kind, the warnings, the fit and validation of every sweep
// (RMS errors, each measured jump against the model's in Hz and %), the
// validation prediction intervals, the figures inline as SVG, the
// configuration in effect and the version. No script, no network.
#ifndef DWELLFIT_ESTIMATOR_RUN_HTML_REPORT_H_
#define DWELLFIT_ESTIMATOR_RUN_HTML_REPORT_H_

#include <string>
#include <vector>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/identification_report.h"
#include "dwellfit/estimator/curves/figures.h"

namespace dwellfit {

inline constexpr char kHtmlReportName[] = "report.html";

// The page of `report`; `figures` are the run's files, of which the SVG
// images are shown (the overview first); `figures_note` says why there are
// none (empty when they were drawn); `units` name the data's units.
std::string ReportToHtml(const IdentificationReport& report, const std::vector<NamedFile>& figures,
                         const std::string& figures_note, const DataUnits& units = {});

// The unit of parameter `index` (docs/model.md, Units) in the data's units
// ("[A]" and "[B]" where unstated): eta_e "mm/(g s^2)", mu2 "1/(mm s)".
std::string ParameterUnit(ModelForm form, int index, const DataUnits& units);

// `text` with &, <, >, " and ' written as HTML entities.
std::string HtmlEscape(const std::string& text);

// The pieces every dwellfit page is made of (identify's, select_model's and
// sensitivity's): a whole self-contained page of `title` around `body`
// (HTML); a table (text cells, escaped here); the SVG images among `files`
// inline, each with its name as caption, those named `first_stem`* first.
std::string HtmlPage(const std::string& title, const std::string& body);
std::string HtmlTable(const std::string& id, const std::vector<std::string>& header,
                      const std::vector<std::vector<std::string>>& rows);
std::string InlineSvgFigures(const std::vector<NamedFile>& files,
                             const std::string& first_stem = "");

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_RUN_HTML_REPORT_H_
