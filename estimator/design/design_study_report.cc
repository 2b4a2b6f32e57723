// design_study's printed table, CSV files and gnuplot figure.
#include <algorithm>
#include <array>
#include <cmath>

#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/design/design_study.h"

namespace dwellfit {
namespace {

// An arm's time to the target [s]; one that did not reach it counts with its
// whole test time (a lower bound).
double TimeOrSpent(const ArmRun& arm) {
  return arm.reached ? arm.time_to_target_seconds : arm.elapsed_seconds;
}

double DwellsOrAll(const ArmRun& arm) {
  return arm.reached ? arm.dwells_to_target : static_cast<double>(arm.dwells.size());
}

struct ArmSummary {
  double median_time = 0.0, median_dwells = 0.0;
  int reached = 0, covered = 0, runs = 0;
  std::array<int, kStudyQuantities> covered_each{};  // seeds whose interval holds the truth
};

ArmSummary Summarise(const std::vector<ArmRun>& arms) {
  ArmSummary s;
  std::vector<double> times, dwells;
  for (const ArmRun& arm : arms) {
    times.push_back(TimeOrSpent(arm));
    dwells.push_back(DwellsOrAll(arm));
    s.reached += arm.reached ? 1 : 0;
    s.covered += arm.covers_all ? 1 : 0;
    for (int i = 0; i < kStudyQuantities; ++i) s.covered_each[i] += arm.covers[i] ? 1 : 0;
    ++s.runs;
  }
  s.median_time = Median(times);
  s.median_dwells = Median(dwells);
  return s;
}

std::string CoverText(const ArmRun& arm) {
  std::string text;
  for (int i = 0; i < kStudyQuantities; ++i) text += arm.covers[i] ? "y" : "n";
  return text;
}

// The last fit's half-widths in % of |value|.
std::string HalfWidths(const ArmRun& arm) {
  for (auto fit = arm.fits.rbegin(); fit != arm.fits.rend(); ++fit) {
    if (!fit->has_intervals) continue;
    std::string text;
    for (int i = 0; i < kStudyQuantities; ++i) {
      text += StringPrintf("%s%.3g", i ? " " : "",
                           100.0 * fit->half_width[i] / std::abs(fit->value[i]));
    }
    return text;
  }
  return "-";
}

}  // namespace

void PrintDesignStudy(const DesignStudyResult& result, const DesignStudyOptions& options,
                      std::ostream& out) {
  out << StringPrintf("\n%s: target half-widths of %s 95 %% intervals", result.case_name.c_str(),
                      options.target.simultaneous ? "simultaneous" : "each quantity's");
  for (int i = 0; i < kStudyQuantities; ++i) {
    out << StringPrintf(" %s %g %%", StudyQuantityName(i),
                        100.0 * options.target.relative_half_width[i]);
  }
  out << StringPrintf("; budget %.0f s\n", options.time_budget_seconds);
  out << StringPrintf("%-6s %-11s %7s %12s %8s %8s  %-6s %s\n", "seed", "arm", "reached", "time_s",
                      "dwells", "fits", "covers", "final half-widths % (alpha_e eta_e w mu1)");
  for (std::size_t k = 0; k < result.standard.size(); ++k) {
    for (const ArmRun* arm : {&result.standard[k], &result.closed_loop[k]}) {
      out << StringPrintf("%-6llu %-11s %7s %12.1f %8.0f %8zu  %-6s %s\n",
                          static_cast<unsigned long long>(arm->seed), arm->arm.c_str(),
                          arm->reached ? "yes" : "no", TimeOrSpent(*arm), DwellsOrAll(*arm),
                          arm->fits.size(), CoverText(*arm).c_str(), HalfWidths(*arm).c_str());
    }
  }
  const ArmSummary st = Summarise(result.standard), cl = Summarise(result.closed_loop);
  for (const auto& [name, s] :
       {std::make_pair("standard", st), std::make_pair("closed_loop", cl)}) {
    out << StringPrintf(
        "median %-11s: time to target %.1f s, %.0f dwells; reached in %d of %d seeds; final "
        "intervals cover the truth in %d of %d (alpha_e %d, eta_e %d, w %d, mu1 %d)\n",
        name, s.median_time, s.median_dwells, s.reached, s.runs, s.covered, s.runs,
        s.covered_each[0], s.covered_each[1], s.covered_each[2], s.covered_each[3]);
  }
  out << StringPrintf(
      "closed loop / standard, median time to target: %.3f (bar <= 0.5); closed loop coverage "
      "%.0f %% (bar >= 90 %%)%s\n",
      cl.median_time / st.median_time, 100.0 * cl.covered / std::max(cl.runs, 1),
      st.reached * 2 > st.runs && cl.reached * 2 > cl.runs
          ? ""
          : "; a median over seeds that did not reach the target is their whole test time, a "
            "lower bound");
}

std::string DesignStudyCsv(const std::vector<DesignStudyResult>& results) {
  std::string csv =
      "case,arm,seed,reached,time_to_target_s,dwells_to_target,elapsed_s,dwells,fits,covers_all";
  for (int i = 0; i < kStudyQuantities; ++i) {
    const char* q = StudyQuantityName(i);
    csv += StringPrintf(",%s,%s_half_width_pct,%s_covers", q, q, q);
  }
  csv += ",end\n";
  for (const DesignStudyResult& result : results) {
    for (const auto* arms : {&result.standard, &result.closed_loop}) {
      for (const ArmRun& arm : *arms) {
        csv += StringPrintf("%s,%s,%llu,%d,%.6g,%d,%.6g,%zu,%zu,%d", result.case_name.c_str(),
                            arm.arm.c_str(), static_cast<unsigned long long>(arm.seed),
                            arm.reached ? 1 : 0, arm.reached ? arm.time_to_target_seconds : NAN,
                            arm.dwells_to_target, arm.elapsed_seconds, arm.dwells.size(),
                            arm.fits.size(), arm.covers_all ? 1 : 0);
        const StudyFit* last = nullptr;
        for (const StudyFit& fit : arm.fits) last = fit.has_intervals ? &fit : last;
        for (int i = 0; i < kStudyQuantities; ++i) {
          csv += last ? StringPrintf(",%.10g,%.6g,%d", last->value[i],
                                     100.0 * last->half_width[i] / std::abs(last->value[i]),
                                     arm.covers[i] ? 1 : 0)
                      : ",,,0";
        }
        csv += "," + arm.end + "\n";
      }
    }
  }
  return csv;
}

std::string DesignStudyFitsCsv(const std::vector<DesignStudyResult>& results) {
  std::string csv = "case,arm,seed,dwells,elapsed_s,status,has_intervals,worst_ratio,met";
  for (int i = 0; i < kStudyQuantities; ++i) {
    csv += StringPrintf(",%s,%s_half_width", StudyQuantityName(i), StudyQuantityName(i));
  }
  csv += "\n";
  for (const DesignStudyResult& result : results) {
    for (const auto* arms : {&result.standard, &result.closed_loop}) {
      for (const ArmRun& arm : *arms) {
        for (const StudyFit& fit : arm.fits) {
          const double ratio = fit.has_intervals ? fit.worst_ratio : NAN;
          csv += StringPrintf("%s,%s,%llu,%d,%.6g,%s,%d,%.6g,%d", result.case_name.c_str(),
                              arm.arm.c_str(), static_cast<unsigned long long>(arm.seed),
                              fit.dwells, fit.elapsed_seconds, FitStatusName(fit.status),
                              fit.has_intervals ? 1 : 0, ratio, fit.met ? 1 : 0);
          for (int i = 0; i < kStudyQuantities; ++i) {
            csv += StringPrintf(",%.8g,%.4g", fit.value[i], fit.half_width[i]);
          }
          csv += "\n";
        }
      }
    }
  }
  return csv;
}

std::string DesignStudyGnuplot(const std::vector<DesignStudyResult>& results,
                               const DesignStudyOptions& options) {
  std::string gp =
      "# The largest 95 % half-width over its target after every fit, over the simulated\n"
      "# test time, every seed of both arms, from design_study_fits.csv.\n"
      "# PNG: gnuplot design_study.gp; SVG: gnuplot -e \"fmt='svg'\" design_study.gp\n"
      "if (!exists(\"fmt\")) fmt = \"png\"\n"
      "if (fmt eq \"svg\") {\n"
      "  set terminal svg size 900,420*N dynamic noenhanced font \"sans,12\" "
      "background \"white\"\n"
      "} else {\n"
      "  set terminal pngcairo size 900,420*N noenhanced font \"sans,10\"\n"
      "}\n"
      "set datafile separator \",\"\nset output \"figure_design_study.\".fmt\n"
      "set logscale y\nset grid\nset key top right\n"
      "set xlabel \"simulated test time [s]\"\n"
      "set ylabel \"largest 95 % half-width / its target\"\n";
  gp = StringPrintf("N = %zu\n", results.size()) + gp;
  gp += StringPrintf("set multiplot layout %zu,1\n", results.size());
  for (const DesignStudyResult& result : results) {
    const std::string c = result.case_name;
    gp += StringPrintf(
        "set title \"%s: closed loop (red) and standard protocol (blue), "
        "%d seeds; target met below 1\"\n",
        c.c_str(), options.seeds);
    gp += StringPrintf(
        "plot \"design_study_fits.csv\" skip 1 using (strcol(1) eq \"%s\" && strcol(2) eq "
        "\"standard\" ? $5 : 1/0):8 with points pt 7 ps 0.4 lc rgb \"#3060c0\" "
        "title \"standard\", \\\n"
        "  \"\" skip 1 using (strcol(1) eq \"%s\" && strcol(2) eq \"closed_loop\" ? $5 : "
        "1/0):8 with points pt 7 ps 0.3 lc rgb \"#c03030\" title \"closed loop\", \\\n"
        "  1 with lines dt 2 lc rgb \"black\" title \"target\"\n",
        c.c_str(), c.c_str());
  }
  return gp + "unset multiplot\nunset output\n";
}

std::string DesignStudyDwellsCsv(const std::vector<DesignStudyResult>& results) {
  std::string csv =
      "case,arm,seed,dwell,sweep,f_hz,level,settle_s,record_s,expected_branch,landed_branch\n";
  for (const DesignStudyResult& result : results) {
    for (const auto* arms : {&result.standard, &result.closed_loop}) {
      for (const ArmRun& arm : *arms) {
        for (std::size_t i = 0; i < arm.dwells.size(); ++i) {
          const StudyDwell& d = arm.dwells[i];
          csv += StringPrintf("%s,%s,%llu,%zu,%s,%.10g,%.10g,%.6g,%.6g,%s,%s\n",
                              result.case_name.c_str(), arm.arm.c_str(),
                              static_cast<unsigned long long>(arm.seed), i + 1, d.sweep.c_str(),
                              d.frequency_hz, d.level, d.settle_seconds, d.record_seconds,
                              d.expected_branch.c_str(), d.landed_branch.c_str());
        }
      }
    }
  }
  return csv;
}

std::vector<NamedFile> DesignStudyFiles(const std::vector<DesignStudyResult>& results,
                                        const DesignStudyOptions& options, bool render,
                                        std::string* warning) {
  const std::string script = DesignStudyGnuplot(results, options);
  std::vector<NamedFile> files = {{kDesignStudyCsvName, DesignStudyCsv(results)},
                                  {kDesignStudyFitsCsvName, DesignStudyFitsCsv(results)},
                                  {"design_study_dwells.csv", DesignStudyDwellsCsv(results)},
                                  {"design_study.gp", script}};
  if (render) {
    const RenderedFigures figures = RenderFigures({{kFigureScriptName, script}, files[1]});
    if (!figures.rendered) *warning = figures.warning;
    for (const NamedFile& image : figures.images) files.push_back(image);
  }
  return files;
}

}  // namespace dwellfit
