#include "dwellfit/estimator/studies/sensitivity_study.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>

#include "boost/algorithm/string/classification.hpp"
#include "boost/algorithm/string/trim.hpp"
#include "boost/crc.hpp"
#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/analysis/parameter_uncertainty.h"
#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/common/text_file.h"
#include "dwellfit/estimator/curves/figures.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/estimator/fit/staged_solve.h"
#include "dwellfit/estimator/run/resolved_run.h"
#include "dwellfit/estimator/studies/replica_run.h"
#include "dwellfit/estimator/studies/study_pages.h"
#include "tbb/parallel_for.h"
#include "tbb/task_arena.h"
#include "yaml-cpp/yaml.h"

namespace dwellfit {
namespace {

// Splits `text` at `separator` outside brackets and quotes.
std::vector<std::string> SplitOutside(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string current;
  int depth = 0;
  char quote = 0;
  for (char c : text) {
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == separator && depth == 0) {
      parts.push_back(current);
      current.clear();
      continue;
    }
    current += c;
  }
  parts.push_back(current);
  return parts;
}

std::string Trim(const std::string& text) {
  return boost::algorithm::trim_copy_if(text, boost::algorithm::is_any_of(" \t"));
}

// The values of every case: the Cartesian product of the axes, the last axis
// varying fastest.
std::vector<std::vector<std::string>> Cases(const std::vector<VaryAxis>& axes) {
  std::vector<std::vector<std::string>> cases = {{}};
  for (const VaryAxis& axis : axes) {
    std::vector<std::vector<std::string>> next;
    for (const auto& prefix : cases) {
      for (const std::string& value : axis.values) {
        next.push_back(prefix);
        next.back().push_back(value);
      }
    }
    cases = std::move(next);
  }
  return cases;
}

// Quoted for CSV when it holds a comma or a quote.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// With `standard_errors` the fit goes the way identify's does
// (EstimateUncertaintyAtMinimum: made a minimum of its cost where a profile
// finds a lower one), and the row takes the linearised standard errors.
void FillEstimates(const IdentifyConfig& config, const ResolvedRun& run,
                   IdentificationResult result, bool standard_errors, FitRow* row) {
  const double omega_ref = config.omega_ref_rad_s.value_or(result.parameters[kNaturalFrequency]);
  ParameterUncertainty u;
  if (standard_errors && result.IsSolutionUsable()) {
    u = EstimateUncertaintyAtMinimum(run.fitted, run.options, omega_ref, &result);
  }
  row->status = FitStatusName(result.status);
  row->cost = result.final_cost;
  row->iterations = result.iterations;
  if (!result.stages.empty()) {
    row->dof =
        result.stages.back().residual_blocks -
        static_cast<int>(std::count(run.options.fixed.begin(), run.options.fixed.end(), false));
  }
  row->estimate = result.parameters;
  row->estimate[kNaturalFrequency] = RadPerSecondToHz(result.parameters[kNaturalFrequency]);
  if (!u.available) return;
  row->standard_error = u.standard_error;
  row->standard_error[kNaturalFrequency] = RadPerSecondToHz(u.standard_error[kNaturalFrequency]);
}

FitRow RunOneFit(const IdentifyConfig& config, const SensitivityOptions& options, int fit) {
  FitRow row;
  row.fit = fit;
  row.case_index = fit / options.replicas;
  row.replica = fit % options.replicas;
  try {
    ResolvedRun run;
    if (options.plan) {
      row.seed = options.first_seed + static_cast<std::uint64_t>(row.replica);
      run = ResolveReplicaRun(config, *options.plan, options.noise, row.seed);
    } else {
      run = ResolveRun(config);
    }
    run.options.solve.solver.num_threads = 1;
    run.multi_start.threads = 1;
    FillEstimates(config, run, FitRun(run).best, options.standard_errors, &row);
  } catch (const InputError&) {
    // This replica's data cannot be fitted (no start found from them).
    row.status = FitStatusName(FitStatus::kInvalidInput);
  }
  return row;
}

bool Usable(const FitRow& row) {
  return row.status == FitStatusName(FitStatus::kConverged) ||
         row.status == FitStatusName(FitStatus::kNoConvergence);
}

std::string ParameterColumn(int i) {
  return i == kNaturalFrequency ? "omega_hz" : ParameterName(i);
}

// One case's block of summary.yaml.
void SummarizeCase(const SensitivityStudy& study, int case_index, std::ostringstream* yaml) {
  std::vector<const FitRow*> rows, usable;
  int converged = 0;
  for (const FitRow& row : study.rows) {
    if (row.case_index != case_index) continue;
    rows.push_back(&row);
    if (Usable(row)) usable.push_back(&row);
    converged += row.status == FitStatusName(FitStatus::kConverged);
  }
  *yaml << "  - case: " << case_index << "\n";
  if (!rows.empty() && !study.axis_keys.empty()) {
    *yaml << "    settings:\n";
    for (size_t j = 0; j < study.axis_keys.size(); ++j) {
      *yaml << "      " << study.axis_keys[j] << ": \"" << rows[0]->settings[j] << "\"\n";
    }
  }
  *yaml << "    fits: " << rows.size() << "\n    usable: " << usable.size()
        << "\n    converged: " << converged << "\n"
        << StringPrintf("    success_rate: %.6g\n",
                        rows.empty() ? 0.0 : static_cast<double>(converged) / rows.size());
  *yaml << "    parameters:\n";
  for (int i = 0; i < kNumParameters; ++i) {
    double sum = 0.0, sum_se = 0.0;
    int with_se = 0;
    for (const FitRow* row : usable) {
      sum += row->estimate[i];
      if (row->standard_error[i] > 0.0) sum_se += row->standard_error[i], ++with_se;
    }
    const double n = static_cast<double>(usable.size());
    const double mean = n > 0 ? sum / n : NAN;
    double squares = 0.0;
    for (const FitRow* row : usable)
      squares += (row->estimate[i] - mean) * (row->estimate[i] - mean);
    *yaml << "      " << ParameterColumn(i) << ": {"
          << StringPrintf("mean: %.10g, std: %.6g, mean_se: %.6g", mean,
                          n > 1 ? std::sqrt(squares / (n - 1)) : 0.0,
                          with_se > 0 ? sum_se / with_se : 0.0);
    if (study.truth) {
      const double truth = (*study.truth)[i];
      *yaml << StringPrintf(", truth: %.10g, bias: %.6g, relative_bias: %.6g", truth, mean - truth,
                            truth != 0.0 ? (mean - truth) / truth : NAN);
    }
    *yaml << "}\n";
  }
}

constexpr char kGiveTheShards[] = "give the folders of the shards";

SensitivityStudy ReadStudyYaml(const std::string& path) {
  SensitivityStudy study;
  try {
    const YAML::Node node = YAML::Load(ReadTextFile(path, kGiveTheShards));
    for (const YAML::Node& key : node["axis_keys"])
      study.axis_keys.push_back(key.as<std::string>());
    study.cases = node["cases"].as<int>();
    study.replicas = node["replicas"].as<int>();
    study.total_fits = node["total_fits"].as<int>();
    if (node["fingerprint"]) study.fingerprint = node["fingerprint"].as<std::string>();
    study.shard = node["shard"].as<int>();
    study.shards = node["shards"].as<int>();
    if (node["truth"]) {
      ParameterVector truth{};
      for (int i = 0; i < kNumParameters; ++i) truth[i] = node["truth"][i].as<double>();
      study.truth = truth;
    }
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, "", "not a study.yaml of a sensitivity run: " + e.msg);
  }
  if (study.shards < 1 || study.shards > 1000000 || study.shard < 0 ||
      study.shard >= study.shards || study.cases < 1 || study.replicas < 1 ||
      study.total_fits != study.cases * study.replicas) {
    throw InputError(path, 0, "shard", "inconsistent sizes; give the folders sensitivity wrote");
  }
  return study;
}

// Splits one CSV line at commas outside double quotes, unquoting fields.
std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') {
      if (quoted && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else {
        quoted = !quoted;
      }
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

double ParseNumber(const std::string& text, const std::string& path, int line) {
  char* end = nullptr;
  // Decimal notation only: strtod alone would take "0x28", "inf" and "nan".
  const bool decimal = text.find_first_not_of("0123456789+-.eE") == std::string::npos;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || !decimal || *end != '\0') {
    throw InputError(path, line, "", "'" + EscapeForMessage(text) + "' is no number");
  }
  return value;
}

// A non-negative integer field (an index or a count).
int ParseCount(const std::string& text, const std::string& path, int line) {
  const double value = ParseNumber(text, path, line);
  if (!(value >= 0.0 && value <= 2e9) || value != std::floor(value)) {
    throw InputError(path, line, "", "'" + EscapeForMessage(text) + "' is no count");
  }
  return static_cast<int>(value);
}

void ReadFitRows(const std::string& path, const SensitivityStudy& shape,
                 std::vector<FitRow>* rows) {
  std::istringstream csv(ReadTextFile(path, kGiveTheShards));
  std::string line;
  std::getline(csv, line);
  const size_t keys = shape.axis_keys.size();
  const size_t columns = 4 + keys + 3 + 2 * kNumParameters + 1;
  for (int number = 2; std::getline(csv, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();  // a CRLF file
    const std::vector<std::string> f = SplitCsvLine(line);
    if (f.size() != columns) {
      throw InputError(path, number, "",
                       StringPrintf("%zu fields, expected %zu", f.size(), columns));
    }
    FitRow row;
    row.fit = ParseCount(f[0], path, number);
    row.case_index = ParseCount(f[1], path, number);
    row.replica = ParseCount(f[2], path, number);
    row.seed = std::strtoull(f[3].c_str(), nullptr, 10);
    row.settings.assign(f.begin() + 4, f.begin() + 4 + keys);
    row.status = f[4 + keys];
    row.cost = ParseNumber(f[5 + keys], path, number);
    row.iterations = ParseCount(f[6 + keys], path, number);
    for (int i = 0; i < kNumParameters; ++i) {
      row.estimate[i] = ParseNumber(f[7 + keys + 2 * i], path, number);
      row.standard_error[i] = ParseNumber(f[8 + keys + 2 * i], path, number);
    }
    row.dof = ParseCount(f.back(), path, number);
    rows->push_back(row);
  }
}

// study.yaml: what MergeShards needs (keys, sizes, shard, truth).
std::string StudyToYaml(const SensitivityStudy& study) {
  std::ostringstream yaml;
  yaml << "# What dwellfit's sensitivity merge needs to join shards.\n";
  yaml << "axis_keys: [";
  for (size_t j = 0; j < study.axis_keys.size(); ++j)
    yaml << (j > 0 ? ", " : "") << '"' << study.axis_keys[j] << '"';
  yaml << "]\ncases: " << study.cases << "\nreplicas: " << study.replicas
       << "\ntotal_fits: " << study.total_fits << "\nshard: " << study.shard
       << "\nshards: " << study.shards << "\nfingerprint: \"" << study.fingerprint << "\"\n";
  if (study.truth) {
    yaml << "truth: [";
    for (int i = 0; i < kNumParameters; ++i)
      yaml << (i > 0 ? ", " : "") << FormatRoundTrip((*study.truth)[i]);
    yaml << "]\n";
  }
  return yaml.str();
}

// The profile (one axis): the cost and every estimate against the axis value;
// converged fits as filled dots, fits stopped at their iteration limit as
// open ones, failed fits as red crosses at the best fit's value. The cost
// panel's line is the 95 % profile threshold F_min (1 + 3.84 / dof) of the
// best usable fit: by Wilks, 2 dF / s^2 <= chi^2_1(0.95) = 3.84 with
// s^2 = 2 F_min / dof (docs/uncertainty.md).
std::string ProfileFigureScript(const SensitivityStudy& study) {
  const FitRow* best = nullptr;
  for (const FitRow& row : study.rows) {
    if (Usable(row) && (best == nullptr || row.cost < best->cost)) best = &row;
  }
  std::ostringstream gp;
  gp << "# Profile: cost and estimates against " << study.axis_keys[0] << "\n"
     << "set output \"profile.\".fmt\nset multiplot layout 2,4 title \"profile over "
     << study.axis_keys[0] << "\"\nset xlabel \"" << study.axis_keys[0] << "\"\n"
     << "converged(x) = strcol('status') eq \"converged\"\n"
     << "stopped(x) = strcol('status') eq \"no_convergence\"\n"
     << "set key bottom right font \",8\"\n";
  for (int i = -1; i < kNumParameters; ++i) {
    const std::string column = i < 0 ? "cost" : ParameterColumn(i);
    const double at_best = best == nullptr ? 0.0 : (i < 0 ? best->cost : best->estimate[i]);
    gp << "set title \"" << column << "\"\nplot 'fits.csv' using (converged(0) ? column(5) : "
       << "NaN):'" << column << "' with points pt 7 title \"converged\", \\\n"
       << "  'fits.csv' using (stopped(0) ? column(5) : NaN):'" << column
       << "' with points pt 6 lc rgb \"#ff7f0e\" title \"iteration limit\", \\\n"
       << StringPrintf("  'fits.csv' using (converged(0) || stopped(0) ? NaN : column(5)):(%.17g) ",
                       at_best)
       << "with points pt 2 ps 1.5 lc rgb \"#d62728\" title \"failed\"";
    if (i < 0 && best != nullptr && best->dof > 0) {
      gp << StringPrintf(
          ", \\\n  %.17g with lines dt 2 lc rgb \"#555555\" title "
          "\"95 %% threshold\"",
          best->cost * (1.0 + 3.841458820694124 / best->dof));
    }
    gp << "\nunset key\n";
  }
  gp << "unset multiplot\nunset output\n";
  return gp.str();
}

// figures.gp: the histogram of every estimate and, with one axis, the
// profile: the cost and every estimate against the axis value.
std::string StudyFigureScript(const SensitivityStudy& study) {
  std::ostringstream gp;
  gp << "# Figures of a dwellfit sensitivity study, from fits.csv. PNG: gnuplot figures.gp;\n"
        "# SVG: gnuplot -e \"fmt='svg'\" figures.gp\n"
        "if (!exists(\"fmt\")) fmt = \"png\"\n"
        "if (fmt eq \"svg\") {\n  set terminal svg size 1100,700 dynamic noenhanced background "
        "\"white\"\n"
        "} else {\n  set terminal pngcairo size 1100,700 noenhanced font \"sans,9\"\n}\n"
        "set datafile separator \",\"\nset style fill solid 0.6 border -1\nset grid\n"
        "ok(x) = (strcol('status') eq \"converged\" || strcol('status') eq \"no_convergence\")\n";
  gp << "set output \"histograms.\".fmt\nset multiplot layout 2,3 title \"estimates over "
     << study.rows.size() << " fits" << (study.truth ? " (red: the truth)" : "") << "\"\n";
  for (int i = 0; i < kNumParameters; ++i) {
    const std::string name = ParameterColumn(i);
    gp << "stats 'fits.csv' using (ok(0) ? column('" << name << "') : NaN) name \"S\" nooutput\n"
       << "w = (S_max > S_min) ? (S_max - S_min) / 30.0 : (abs(S_max) > 0 ? abs(S_max) * 1e-6 : "
          "1e-6)\n"
       << "set title \"" << name << "\"\nset xtics rotate by -30\n";
    if (study.truth) {
      gp << StringPrintf(
          "set arrow 1 from %.17g, graph 0 to %.17g, graph 1 nohead lw 2 lc rgb "
          "\"#d62728\"\n",
          (*study.truth)[i], (*study.truth)[i]);
    }
    gp << "plot 'fits.csv' using (ok(0) ? w * floor(column('" << name
       << "') / w + 0.5) : NaN):(1.0) smooth frequency with boxes notitle\n";
  }
  gp << "unset multiplot\nunset output\nunset arrow 1\n";
  if (study.axis_keys.size() == 1) gp << ProfileFigureScript(study);
  return gp.str();
}

// StudyFingerprint's text of the plan: truth, sweeps and noise, to the last bit.
std::string PlanText(const DwellPlan& plan) {
  std::string text = "plan truth:";
  for (double value : plan.truth) text += " " + FormatRoundTrip(value);
  for (const SweepPlan& sweep : plan.sweeps) {
    text += StringPrintf("\nsweep %s %s %s %s %s %s %s %d", sweep.id.c_str(),
                         SweepKindName(sweep.kind), FormatRoundTrip(sweep.held_a_base).c_str(),
                         FormatRoundTrip(sweep.held_frequency_hz).c_str(),
                         FormatRoundTrip(sweep.from).c_str(), FormatRoundTrip(sweep.to).c_str(),
                         FormatRoundTrip(sweep.step).c_str(), static_cast<int>(sweep.start_branch));
    for (SweepDirection direction : sweep.directions) text += SweepDirectionName(direction);
  }
  return text + "\nplan noise: " + FormatRoundTrip(plan.noise.relative_sigma);
}

// SensitivityStudy::fingerprint of a study of `configs` (one per case).
std::string StudyFingerprint(const SensitivityOptions& options,
                             const std::vector<IdentifyConfig>& configs) {
  std::string text = StringPrintf("replicas %d noise %s first_seed %llu standard_errors %d\n",
                                  options.replicas, FormatRoundTrip(options.noise).c_str(),
                                  static_cast<unsigned long long>(options.first_seed),
                                  options.standard_errors ? 1 : 0);
  for (const IdentifyConfig& config : configs) text += ConfigToYaml(config) + "\n---\n";
  if (options.plan) text += PlanText(*options.plan);
  boost::crc_32_type crc;
  crc.process_bytes(text.data(), text.size());
  return StringPrintf("%08x", crc.checksum());
}

}  // namespace

std::vector<VaryAxis> ParseVaryFlag(const std::string& flag_value, const std::string& origin) {
  std::vector<VaryAxis> axes;
  if (Trim(flag_value).empty()) return axes;
  for (const std::string& part : SplitOutside(flag_value, ';')) {
    const size_t equals = part.find('=');
    VaryAxis axis;
    axis.key = Trim(part.substr(0, equals));
    if (equals == std::string::npos || axis.key.empty()) {
      throw InputError(origin, 0, axis.key,
                       "'" + part +
                           "' is not key=value1|value2|...; e.g. "
                           "'penalties.bifurcation_range.exponent=2|4|10'");
    }
    for (const std::string& value : SplitOutside(part.substr(equals + 1), '|')) {
      if (Trim(value).empty()) {
        throw InputError(origin, 0, axis.key, "an empty value in '" + part + "'");
      }
      axis.values.push_back(Trim(value));
    }
    for (const VaryAxis& other : axes) {
      if (other.key == axis.key) throw InputError(origin, 0, axis.key, "the key is varied twice");
    }
    axes.push_back(axis);
  }
  return axes;
}

bool SensitivityOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& text) {
    *why = text;
    return false;
  };
  if (replicas < 1) return fail("--replicas must be >= 1");
  if (!plan && replicas != 1)
    return fail("--replicas needs --plan (replicas are noisy simulations of a plan)");
  if (!(noise >= 0.0) || !std::isfinite(noise)) return fail("--noise must be >= 0");
  if (threads < 1) return fail("--threads must be >= 1");
  if (shards < 1 || shard < 0 || shard >= shards)
    return fail(StringPrintf("--shard %d/%d: need 0 <= k < N", shard, shards));
  return true;
}

SensitivityStudy RunSensitivityStudy(const SensitivityOptions& options, const Progress& progress) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("flags", 0, "", why);
  const auto start = std::chrono::steady_clock::now();
  SensitivityStudy study;
  for (const VaryAxis& axis : options.vary) study.axis_keys.push_back(axis.key);
  const std::vector<std::vector<std::string>> cases = Cases(options.vary);
  std::vector<IdentifyConfig> configs;  // loaded up front: a bad value fails at once
  for (const auto& values : cases) {
    std::vector<ConfigOverride> overrides = options.overrides;
    for (size_t j = 0; j < values.size(); ++j)
      overrides.push_back({options.vary[j].key, values[j], "--vary"});
    configs.push_back(LoadIdentifyConfig(options.config_path, overrides));
  }
  // At most kMaxFitsPerRun rows in memory; more is a study to shard.
  constexpr std::int64_t kMaxFitsPerRun = 1000000;
  const std::int64_t total = static_cast<std::int64_t>(cases.size()) * options.replicas;
  if (total > std::numeric_limits<int>::max() || total / options.shards > kMaxFitsPerRun) {
    throw InputError(
        "--replicas", 0, "",
        StringPrintf("%zu cases x %d replicas = %lld fits, %lld in this run; a run "
                     "holds at most %lld: give fewer, or split the study (--shard k/N)",
                     cases.size(), options.replicas, static_cast<long long>(total),
                     static_cast<long long>(total / options.shards),
                     static_cast<long long>(kMaxFitsPerRun)));
  }
  study.cases = static_cast<int>(cases.size());
  study.replicas = options.replicas;
  study.total_fits = static_cast<int>(total);
  study.fingerprint = StudyFingerprint(options, configs);
  study.shard = options.shard;
  study.shards = options.shards;
  if (options.plan) {
    study.truth = options.plan->truth;
    (*study.truth)[kNaturalFrequency] = RadPerSecondToHz(options.plan->truth[kNaturalFrequency]);
  }
  std::vector<int> fits;
  for (int i = options.shard; i < study.total_fits; i += options.shards) fits.push_back(i);
  study.rows.resize(fits.size());
  const int count = static_cast<int>(fits.size());
  std::atomic<int> done{0};
  auto run_fit = [&](int k) {
    study.rows[k] = RunOneFit(configs[fits[k] / options.replicas], options, fits[k]);
    study.rows[k].settings = cases[fits[k] / options.replicas];
    const int finished = ++done;
    if (progress) progress(finished, count);
  };
  // Threads beyond the machine's would only make TBB warn.
  tbb::task_arena(std::min({options.threads, count, tbb::this_task_arena::max_concurrency()}))
      .execute([&] { tbb::parallel_for(0, count, run_fit, tbb::simple_partitioner()); });
  study.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return study;
}

std::string FitsToCsv(const SensitivityStudy& study) {
  std::ostringstream csv;
  csv << "fit,case,replica,seed";
  for (const std::string& key : study.axis_keys) csv << ',' << CsvField(key);
  csv << ",status,cost,iterations";
  for (int i = 0; i < kNumParameters; ++i) {
    csv << ',' << ParameterColumn(i) << ',' << ParameterColumn(i) << "_se";
  }
  csv << ",dof\n";
  for (const FitRow& row : study.rows) {
    csv << row.fit << ',' << row.case_index << ',' << row.replica << ',' << row.seed;
    for (const std::string& value : row.settings) csv << ',' << CsvField(value);
    csv << ',' << row.status << ',' << FormatRoundTrip(row.cost) << ',' << row.iterations;
    for (int i = 0; i < kNumParameters; ++i) {
      csv << ',' << FormatRoundTrip(row.estimate[i]) << ','
          << FormatRoundTrip(row.standard_error[i]);
    }
    csv << ',' << row.dof << '\n';
  }
  return csv.str();
}

std::string SummaryToYaml(const SensitivityStudy& study) {
  std::ostringstream yaml;
  yaml << "# dwellfit sensitivity study: per case, over the usable fits (status converged or "
          "no_convergence).\n# success_rate = converged / fits; bias = mean - truth (the "
          "plan's). omega in Hz.\n";
  yaml << "fits: " << study.rows.size() << "\ncases:\n";
  for (int c = 0; c < study.cases; ++c) SummarizeCase(study, c, &yaml);
  return yaml.str();
}

SensitivityStudy MergeShards(const std::vector<std::string>& folders) {
  if (folders.empty()) throw InputError("--merge", 0, "", "give the shards' folders");
  SensitivityStudy merged = ReadStudyYaml(folders[0] + "/study.yaml");
  std::vector<bool> seen(merged.shards, false);
  for (const std::string& folder : folders) {
    const SensitivityStudy shard = ReadStudyYaml(folder + "/study.yaml");
    if (shard.axis_keys != merged.axis_keys || shard.cases != merged.cases ||
        shard.replicas != merged.replicas || shard.shards != merged.shards) {
      throw InputError(folder + "/study.yaml", 0, "",
                       "not a shard of the same study as " + folders[0]);
    }
    if (shard.fingerprint != merged.fingerprint) {
      throw InputError(folder + "/study.yaml", 0, "fingerprint",
                       "'" + shard.fingerprint + "' differs from " + folders[0] + "'s '" +
                           merged.fingerprint +
                           "': the shards were run with other settings (config, --set, --vary, "
                           "plan, --noise, --first_seed or --replicas); merge shards of one study");
    }
    if (seen[shard.shard]) {
      throw InputError(folder + "/study.yaml", 0, "shard",
                       StringPrintf("shard %d is given twice", shard.shard));
    }
    seen[shard.shard] = true;
    ReadFitRows(folder + "/fits.csv", merged, &merged.rows);
  }
  for (int k = 0; k < merged.shards; ++k) {
    if (!seen[k]) {
      throw InputError("--merge", 0, "", StringPrintf("shard %d/%d is missing", k, merged.shards));
    }
  }
  std::sort(merged.rows.begin(), merged.rows.end(),
            [](const FitRow& x, const FitRow& y) { return x.fit < y.fit; });
  for (size_t i = 0; i < merged.rows.size(); ++i) {
    if (i > 0 && merged.rows[i].fit == merged.rows[i - 1].fit) {
      throw InputError(
          "--merge", 0, "",
          StringPrintf("fit %d is given twice in the shards' fits.csv", merged.rows[i].fit));
    }
    if (merged.rows[i].fit != static_cast<int>(i)) {
      throw InputError("--merge", 0, "",
                       StringPrintf("fit %zu is missing from the shards' fits.csv", i));
    }
  }
  if (static_cast<int>(merged.rows.size()) != merged.total_fits) {
    throw InputError("--merge", 0, "", "the shards hold more fits than the study");
  }
  merged.shard = 0;
  merged.shards = 1;
  return merged;
}

std::vector<std::pair<std::string, std::string>> StudyFiles(const SensitivityStudy& study,
                                                            bool figures, std::ostream& warnings) {
  std::vector<NamedFile> files = {{"fits.csv", FitsToCsv(study)},
                                  {"summary.yaml", SummaryToYaml(study)},
                                  {"study.yaml", StudyToYaml(study)}};
  if (figures) {
    files.emplace_back(kFigureScriptName, StudyFigureScript(study));
    const RenderedFigures rendered = RenderFigures({files[0], files.back()});
    if (rendered.rendered) {
      files.insert(files.end(), rendered.images.begin(), rendered.images.end());
    } else {
      warnings << "warning: " << rendered.warning << "\n";
    }
  }
  files.emplace_back("report.html", StudyToHtml(study, files));
  return files;
}

Progress MakeProgressPrinter(std::ostream& out, bool terminal) {
  auto mutex = std::make_shared<std::mutex>();
  auto last_tenth = std::make_shared<int>(-1);
  return [&out, terminal, mutex, last_tenth](int done, int total) {
    std::lock_guard<std::mutex> lock(*mutex);
    const int percent = total > 0 ? 100 * done / total : 100;
    if (terminal) {
      const int width = 40;
      const int filled = width * percent / 100;
      out << '\r' << '[' << std::string(filled, '#') << std::string(width - filled, ' ') << "] "
          << StringPrintf("%3d%% %d/%d fits", percent, done, total) << (done == total ? "\n" : "")
          << std::flush;
    } else if (percent / 10 > *last_tenth) {
      *last_tenth = percent / 10;
      out << StringPrintf("%d/%d fits (%d%%)\n", done, total, percent) << std::flush;
    }
  };
}

}  // namespace dwellfit
