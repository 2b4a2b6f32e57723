// report.html of the study tools, from html_report.h's pieces: select_model's
// (the recommendation and its reason, the rule, the warnings, every variant's
// held-out scores, the whole Markdown report) and a sensitivity study's (the
// study's size and per case the fits and each estimate's mean, spread and
// bias as summary.yaml holds them, with the figures inline).
#ifndef DWELLFIT_ESTIMATOR_STUDIES_STUDY_PAGES_H_
#define DWELLFIT_ESTIMATOR_STUDIES_STUDY_PAGES_H_

#include <string>
#include <vector>

#include "dwellfit/estimator/curves/figures.h"
#include "dwellfit/estimator/studies/model_selection.h"
#include "dwellfit/estimator/studies/sensitivity_study.h"

namespace dwellfit {

std::string ModelSelectionToHtml(const ModelSelectionReport& report, const std::string& markdown);

// `files`: the study's files (summary.yaml and the figures among them).
std::string StudyToHtml(const SensitivityStudy& study, const std::vector<NamedFile>& files);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_STUDY_PAGES_H_
