// ModelSelectionCsv and ModelSelectionMarkdown: the study's tables.
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/studies/model_selection.h"

namespace dwellfit {
namespace {

// A number for a table: "%.4g", "-" when not finite.
std::string Cell(double value, const char* format = "%.4g") {
  // + 0.0: a parameter held at 0 and reflected (-0) prints as 0.
  return std::isfinite(value) ? StringPrintf(format, value + 0.0) : std::string("-");
}

double MaxOf(const std::vector<double>& values) {
  double max = std::numeric_limits<double>::quiet_NaN();
  for (double v : values) max = std::isnan(max) || v > max ? v : max;
  return max;
}

std::string FitCounts(const VariantResult& v) {
  return StringPrintf("%zu (%d / %d)", v.fits.size(), v.fits_not_converged, v.fits_failed);
}

void MainTable(const ModelSelectionReport& report, std::ostream& out) {
  out << "| variant | k | status | cost | data cost | dwells | AIC | BIC | w [Hz] | "
         "validate: jump-down median % | CV jump-down median % | CV jump-down max % | "
         "CV jump-up median % | CV relative RMS median | fits (not converged / failed) |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < report.variants.size(); ++i) {
    const VariantResult& v = report.variants[i];
    const VariantFit& fit = v.fits[0];
    out << "| " << v.variant.Name()
        << (static_cast<int>(i) == report.recommended ? " **(recommended)**" : "") << " | "
        << v.free_parameters << " | " << FitStatusName(fit.status) << " | "
        << Cell(fit.final_cost, "%.6g") << " | " << Cell(fit.data_cost, "%.6g") << " | "
        << fit.dwells << " | " << Cell(v.aic, "%.1f") << " | " << Cell(v.bic, "%.1f") << " | "
        << Cell(RadPerSecondToHz(fit.parameters[kNaturalFrequency]), "%.3f") << " | "
        << Cell(MedianOf(v.validation.jump_down_percent), "%.2f") << " | "
        << Cell(MedianOf(v.cross_validation.jump_down_percent), "%.2f") << " | "
        << Cell(MaxOf(v.cross_validation.jump_down_percent), "%.2f") << " | "
        << Cell(MedianOf(v.cross_validation.jump_up_percent), "%.2f") << " | "
        << Cell(MedianOf(v.cross_validation.relative_rms), "%.3f") << " | " << FitCounts(v)
        << " |\n";
  }
}

std::string Joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// Per held-out level: the training set and each variant's jump-down errors.
void FoldTable(const ModelSelectionReport& report, std::ostream& out) {
  if (report.variants.empty() || report.variants[0].folds.empty()) return;
  out << "\n## Held-out jump-down error by level (%)\n\n| level | trained on |";
  for (std::size_t i = 0; i < report.variants.size(); ++i)
    out << " " << report.variants[i].variant.Name() << " |";
  out << "\n|---|---|";
  for (std::size_t i = 0; i < report.variants.size(); ++i) out << "---|";
  out << "\n";
  const VariantResult& first = report.variants[0];
  for (std::size_t level = 0; level < first.folds.size(); ++level) {
    const CrossValidationFold& fold = first.folds[level];
    out << "| " << fold.held_out_level << " | " << Joined(first.fits[fold.fit].fitted_sweeps)
        << " |";
    for (const VariantResult& v : report.variants) {
      std::string cell;
      for (double e : v.folds[level].errors.jump_down_percent) {
        cell += (cell.empty() ? "" : ", ") + StringPrintf("%.2f", e);
      }
      out << " " << (cell.empty() ? "-" : cell) << " |";
    }
    out << "\n";
  }
}

// Every fit with its status, so that none that failed passes unseen.
void FitTable(const ModelSelectionReport& report, std::ostream& out) {
  out << "\n## Every fit\n\n| variant | fitted sweeps | status | cost | iterations | eta_e | mu1 "
         "| mu2 | delta | alpha | w [Hz] | message "
         "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const VariantResult& v : report.variants) {
    for (const VariantFit& fit : v.fits) {
      const ParameterVector& p = fit.parameters;
      out << "| " << v.variant.Name() << " | " << Joined(fit.fitted_sweeps) << " | "
          << FitStatusName(fit.status) << " | " << Cell(fit.final_cost, "%.6g") << " | "
          << fit.iterations << " | " << Cell(p[kEtaE]) << " | " << Cell(p[kMu1]) << " | "
          << Cell(p[kMu2]) << " | " << Cell(p[kDelta]) << " | " << Cell(p[kAlpha]) << " | "
          << Cell(RadPerSecondToHz(p[kNaturalFrequency]), "%.3f") << " | "
          << (fit.status == FitStatus::kConverged ? "" : fit.message) << " |\n";
    }
  }
}

}  // namespace

std::string ModelSelectionCsv(const ModelSelectionReport& report) {
  std::ostringstream out;
  out << "variant,delta,mu2,omega_hz,free_parameters,status,final_cost,data_cost,dwells,aic,bic,"
         "eta_e,mu1,mu2_fitted,delta_fitted,alpha,w_hz,validate_jump_down_median_pct,"
         "validate_jump_up_median_pct,validate_relative_rms_median,cv_levels,cv_jump_down_median_"
         "pct,cv_jump_down_max_pct,cv_jump_up_median_pct,cv_relative_rms_median,fits,"
         "fits_not_converged,fits_failed,eligible,recommended\n";
  for (std::size_t i = 0; i < report.variants.size(); ++i) {
    const VariantResult& v = report.variants[i];
    const VariantFit& fit = v.fits[0];
    const ParameterVector& p = fit.parameters;
    out << "\"" << v.variant.Name() << "\"," << v.variant.delta.text << "," << v.variant.mu2.text
        << "," << v.variant.omega.text << "," << v.free_parameters << ","
        << FitStatusName(fit.status)
        << StringPrintf(",%.10g,%.10g,%d,%.10g,%.10g", fit.final_cost, fit.data_cost, fit.dwells,
                        v.aic, v.bic)
        << StringPrintf(",%.10g,%.10g,%.10g,%.10g,%.10g,%.10g", p[kEtaE] + 0.0, p[kMu1] + 0.0,
                        p[kMu2] + 0.0, p[kDelta] + 0.0, p[kAlpha] + 0.0, RadPerSecondToHz(p[kNaturalFrequency]))
        << StringPrintf(",%.6g,%.6g,%.6g", MedianOf(v.validation.jump_down_percent),
                        MedianOf(v.validation.jump_up_percent), MedianOf(v.validation.relative_rms))
        << StringPrintf(",%zu,%.6g,%.6g,%.6g,%.6g", v.folds.size(),
                        MedianOf(v.cross_validation.jump_down_percent),
                        MaxOf(v.cross_validation.jump_down_percent),
                        MedianOf(v.cross_validation.jump_up_percent),
                        MedianOf(v.cross_validation.relative_rms))
        << StringPrintf(",%zu,%d,%d,%s,%s\n", v.fits.size(), v.fits_not_converged, v.fits_failed,
                        v.eligible ? "true" : "false",
                        static_cast<int>(i) == report.recommended ? "true" : "false");
  }
  return out.str();
}

std::string ModelSelectionMarkdown(const ModelSelectionReport& report) {
  std::ostringstream out;
  out << "# Model selection\n\nConfig: `" << report.config_path
      << "`. Cross-validation: " << CrossValidationSchemeName(report.selection.scheme)
      << " (training: " << CrossValidationTrainingName(report.selection.training) << ") over "
      << report.pool_levels.size() << " levels: " << Joined(report.pool_levels) << ".\n\n"
      << "Criteria: independent Gaussian residuals of the last stage with the variance "
         "estimated, -2 ln L = n (ln(2 pi RSS/n) + 1), RSS = 2 x data cost (no penalties), n = "
         "fitted dwells, k = free parameters; AIC = -2 ln L + 2k, BIC = -2 ln L + k ln n. Jump "
         "errors: |model - measured| / measured of each held-out measured jump (bracket centre; "
         "a missing fold or an unusable fit counts 100 %). Relative RMS: of the held-out "
         "amplitudes.\n\n";
  MainTable(report, out);
  out << "\nRule: " << report.rule << ".\n\n**" << report.verdict << "**\n";
  FoldTable(report, out);
  FitTable(report, out);
  return out.str();
}

}  // namespace dwellfit
