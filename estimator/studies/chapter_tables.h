// The chapter's Tables 3.3 and 3.4 reproduced: the identification with and
// without the bifurcation-range penalty, on the numerical case (against its
// known truth) and on measured data (percent difference between the two
// estimates, and each level's predicted jump-down frequency beside its
// measured bracket), as one Markdown report.
#ifndef DWELLFIT_ESTIMATOR_STUDIES_CHAPTER_TABLES_H_
#define DWELLFIT_ESTIMATOR_STUDIES_CHAPTER_TABLES_H_

#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {

// `numerical`: a config whose data were simulated from `truth`; `measured`:
// a config on measured data. "With penalty" runs each config with its
// penalties and the bifurcation-range penalty enabled; "without" disables
// every penalty. Deterministic: the same inputs give the same text.
std::string ChapterTablesMarkdown(const IdentifyConfig& numerical, const ParameterVector& truth,
                                  const IdentifyConfig& measured);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_STUDIES_CHAPTER_TABLES_H_
