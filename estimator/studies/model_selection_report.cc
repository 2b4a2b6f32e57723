// ModelSelectionCsv and ModelSelectionMarkdown: the study's tables.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "boost/algorithm/string/join.hpp"
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
  return values.empty() ? std::numeric_limits<double>::quiet_NaN()
                        : *std::max_element(values.begin(), values.end());
}

// "2.13 (4.05 Hz)": a median error in % with its Hz.
std::string PercentAndHz(double percent, double hz) {
  if (!std::isfinite(percent)) return "-";
  return StringPrintf("%.2f (%.3g Hz)", percent, hz);
}

void MainTable(const ModelSelectionReport& report, std::ostream& out) {
  out << "| variant | k | status | cost | BIC | w [Hz] | jump-down median % (Hz) | jump-up "
         "median % (Hz) | upper-branch amplitude median % | relative RMS median | "
         "validate: jump-down median % | stable | near-best of 3 | fits (not converged / "
         "failed) |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < report.variants.size(); ++i) {
    const VariantResult& v = report.variants[i];
    const VariantFit& fit = v.fits[0];
    const PredictionErrors& scored =
        v.cross_validation.relative_rms.empty() ? v.validation : v.cross_validation;
    out << "| " << v.variant.Name()
        << (static_cast<int>(i) == report.recommended ? " **(recommended)**" : "") << " | "
        << v.free_parameters << " | " << FitStatusName(fit.status) << " | "
        << Cell(fit.final_cost, "%.6g") << " | " << Cell(v.bic, "%.1f") << " | "
        << Cell(RadPerSecondToHz(fit.parameters[kNaturalFrequency]), "%.3f") << " | "
        << PercentAndHz(v.jump_down_percent, v.jump_down_hz) << " | "
        << PercentAndHz(v.jump_up_percent, v.jump_up_hz) << " | "
        << Cell(v.upper_branch_percent, "%.1f") << " | "
        << Cell(MedianOf(scored.relative_rms), "%.3f") << " | "
        << Cell(MedianOf(v.validation.jump_down_percent), "%.2f") << " | "
        << (v.unstable ? "no" : "yes") << " | "
        << (v.near_best < 0 ? std::string("not a candidate") : std::to_string(v.near_best)) << " | "
        << StringPrintf("%zu (%d / %d)", v.fits.size(), v.fits_not_converged, v.fits_failed)
        << " |\n";
  }
}

std::string Joined(const std::vector<std::string>& names) {
  return boost::algorithm::join(names, ", ");
}

// A held-out value with its unit: Hz for jumps, the data's unit for amplitudes.
std::string Value(const HeldOutPrediction& p, double value) {
  if (!std::isfinite(value)) return "-";
  return p.quantity == HeldOutQuantity::kUpperBranchAmplitude ? StringPrintf("%.4g", value)
                                                              : StringPrintf("%.2f Hz", value);
}

// Per held-out level, for one variant: every predicted quantity, measured
// and predicted (Hz or the amplitude's unit), the error in the same unit and
// in %, and the 95 % prediction interval.
void LevelTable(const ModelSelectionReport& report, std::size_t index, std::ostream& out) {
  const VariantResult& v = report.variants[index];
  out << "\n### " << v.variant.Name()
      << (static_cast<int>(index) == report.recommended ? " (recommended)" : "") << "\n\n"
      << "| level | trained on | sweep | quantity | measured | predicted | error | error % | "
         "95 % interval +/- | s_p | s_m | inside |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const CrossValidationFold& fold : v.folds) {
    for (const HeldOutPrediction& p : fold.predictions) {
      const bool known = std::isfinite(p.predicted);
      out << "| " << fold.held_out_level << " | " << Joined(v.fits[fold.fit].fitted_sweeps) << " | "
          << p.sweep << " | " << HeldOutQuantityName(p.quantity) << " | " << Value(p, p.measured)
          << " | " << (known ? Value(p, p.predicted) : std::string("no fold / no fit")) << " | "
          << (known ? Value(p, p.predicted - p.measured) : std::string("-")) << " | "
          << Cell(p.ErrorPercent(), "%+.2f") << " | " << Value(p, p.half_width) << " | "
          << Value(p, p.parameter_sd) << " | " << Value(p, p.model_sd) << " | "
          << (p.inside ? "yes" : "no") << " |\n";
    }
  }
}

std::string CoverageCell(const IntervalCoverage& c, bool hz) {
  if (c.total == 0) return "-";
  return StringPrintf("%d / %d", c.inside, c.total) + " | " +
         (std::isfinite(c.median_half_width)
              ? StringPrintf(hz ? "%.3g Hz (%.2f %%)" : "%.3g (%.1f %%)", c.median_half_width,
                             c.median_half_width_percent)
              : std::string("-"));
}

// The 95 % prediction intervals' coverage per variant, and the per-level tables.
void FoldTables(const ModelSelectionReport& report, std::ostream& out) {
  if (report.variants.empty() || report.variants[0].folds.empty()) return;
  out << "\n## Held-out levels: 95 % prediction intervals\n\n"
         "Interval: predicted +/- 1.96 sqrt(s_p^2 + s_m^2); s_p the fold fit's parameter "
         "uncertainty (dwells-alone covariance, delta method), s_m the predicted value times "
         "the RMS relative error of the same quantity at every other held-out level (the model "
         "error the cross-validation shows). Inside: the measured value (a jump's bracket "
         "centre, the mean upper-branch amplitude) lies within the interval.\n\n"
         "| variant | jump-down inside | median half-width | jump-up inside | median half-width "
         "| upper-branch amplitude inside | median half-width |\n"
         "|---|---|---|---|---|---|---|\n";
  for (const VariantResult& v : report.variants) {
    out << "| " << v.variant.Name() << " | " << CoverageCell(v.jump_down_coverage, true) << " | "
        << CoverageCell(v.jump_up_coverage, true) << " | "
        << CoverageCell(v.upper_branch_coverage, false) << " |\n";
  }
  for (std::size_t i = 0; i < report.variants.size(); ++i) LevelTable(report, i, out);
}

// Each free parameter's spread over the variant's usable fits.
void SpreadTable(const ModelSelectionReport& report, std::ostream& out) {
  out << "\n## Parameters across the fits\n\n"
         "| variant | parameter | min | median | max | (max - min) / median |\n"
         "|---|---|---|---|---|---|\n";
  for (const VariantResult& v : report.variants) {
    for (const ParameterSpread& s : v.spread) {
      out << "| " << v.variant.Name() << " | " << s.name << " | " << Cell(s.min) << " | "
          << Cell(s.median) << " | " << Cell(s.max) << " | "
          << Cell(100.0 * s.relative_range, "%.1f %%") << " |\n";
    }
  }
}

// Whether the study compares members of the family (model_form.h).
bool ComparesMembers(const ModelSelectionReport& report) {
  return std::any_of(report.variants.begin(), report.variants.end(),
                     [](const VariantResult& v) { return v.variant.form.family_terms(); });
}

// Every fit with its status, so that none that failed passes unseen.
void FitTable(const ModelSelectionReport& report, std::ostream& out) {
  const bool members = ComparesMembers(report);
  out << "\n## Every fit\n\n| variant | fitted sweeps | status | cost | iterations | eta_e | mu1 "
         "| "
      << (members ? "mu2 or mu3 | delta or alpha5" : "mu2 | delta")
      << " | alpha | w [Hz] | message "
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
         "fits_not_converged,fits_failed,eligible,recommended,jump_down_median_hz,"
         "jump_up_median_hz,upper_branch_median_pct,unstable,near_best,"
         "jump_down_interval_inside,jump_down_interval_total,jump_down_interval_median_half_"
         "width_hz";
  // A study over the family's members names each variant's terms; the
  // columns delta, mu2, mu2_fitted and delta_fitted then hold alpha5 and mu3
  // where these say so.
  const bool members = ComparesMembers(report);
  out << (members ? ",backbone,damping\n" : "\n");
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
                        p[kMu2] + 0.0, p[kDelta] + 0.0, p[kAlpha] + 0.0,
                        RadPerSecondToHz(p[kNaturalFrequency]))
        << StringPrintf(",%.6g,%.6g,%.6g", MedianOf(v.validation.jump_down_percent),
                        MedianOf(v.validation.jump_up_percent), MedianOf(v.validation.relative_rms))
        << StringPrintf(",%zu,%.6g,%.6g,%.6g,%.6g", v.folds.size(),
                        MedianOf(v.cross_validation.jump_down_percent),
                        MaxOf(v.cross_validation.jump_down_percent),
                        MedianOf(v.cross_validation.jump_up_percent),
                        MedianOf(v.cross_validation.relative_rms))
        << StringPrintf(",%zu,%d,%d,%s,%s", v.fits.size(), v.fits_not_converged, v.fits_failed,
                        v.eligible ? "true" : "false",
                        static_cast<int>(i) == report.recommended ? "true" : "false")
        << StringPrintf(",%.6g,%.6g,%.6g,%s,%d,%d,%d,%.6g", v.jump_down_hz, v.jump_up_hz,
                        v.upper_branch_percent, v.unstable ? "true" : "false", v.near_best,
                        v.jump_down_coverage.inside, v.jump_down_coverage.total,
                        v.jump_down_coverage.median_half_width);
    if (members) {
      out << "," << BackboneTermName(v.variant.form.backbone) << ","
          << DampingTermName(v.variant.form.damping);
    }
    out << "\n";
  }
  return out.str();
}

std::string ModelSelectionLevelsCsv(const ModelSelectionReport& report) {
  std::ostringstream out;
  out << "variant,level,trained_on,sweep,quantity,unit,measured,predicted,error,error_pct,"
         "half_width_95,parameter_sd,model_sd,inside\n";
  for (const VariantResult& v : report.variants) {
    for (const CrossValidationFold& fold : v.folds) {
      for (const HeldOutPrediction& p : fold.predictions) {
        const bool amplitude = p.quantity == HeldOutQuantity::kUpperBranchAmplitude;
        out << "\"" << v.variant.Name() << "\"," << fold.held_out_level << ",\""
            << Joined(v.fits[fold.fit].fitted_sweeps) << "\"," << p.sweep << ","
            << HeldOutQuantityName(p.quantity) << "," << (amplitude ? "data" : "Hz")
            << StringPrintf(",%.10g,%.10g,%.10g,%.6g,%.10g,%.10g,%.10g,%s\n", p.measured,
                            p.predicted, p.predicted - p.measured, p.ErrorPercent(), p.half_width,
                            p.parameter_sd, p.model_sd, p.inside ? "true" : "false");
      }
    }
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
         "a missing fold or an unusable fit counts 100 %), in % and Hz. Upper-branch amplitude: "
         "the mean measured amplitude of an up-sweep's dwells above half its peak, before its "
         "jump-down, against the model's on that branch (|error| in %). Relative RMS: of every "
         "held-out amplitude. Scores: medians over the held-out levels (leave-one-level-out; "
         "without it, the validate sweeps).\n\n";
  MainTable(report, out);
  out << "\nRule: " << report.rule << ".\n\n**" << report.verdict << "**\n";
  for (const std::string& warning : report.warnings) out << "\n- WARNING: " << warning << "\n";
  FoldTables(report, out);
  SpreadTable(report, out);
  FitTable(report, out);
  return out.str();
}

std::string RecommendedConfigYaml(const IdentifyConfig& config,
                                  const ModelSelectionReport& report) {
  if (report.recommended < 0) return "";
  const VariantResult& chosen = report.variants[report.recommended];
  std::ostringstream out;
  out << "# The variant select_model recommends for " << config.config_path << ":\n#   "
      << chosen.variant.Name() << "\n#   " << report.verdict << "\n"
      << "# Rule: " << report.rule << ".\n"
      << "# Run it as is: identify --config <this file>. Paths are absolute.\n"
      << ConfigToYaml(WithVariant(config, chosen.variant));
  return out.str();
}

}  // namespace dwellfit
