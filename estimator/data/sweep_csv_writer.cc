#include "dwellfit/estimator/data/sweep_csv_writer.h"

#include <unistd.h>

#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/residuals/model/model_parameters.h"
#include "glog/logging.h"

namespace dwellfit {

std::string FormatRoundTrip(double value) {
  char buffer[64];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  CHECK(result.ec == std::errc()) << "64 characters hold any double";
  return std::string(buffer, result.ptr);
}

std::string FormatFrequencyHz(double omega_rad_s) {
  const double hz = RadPerSecondToHz(omega_rad_s);
  for (int digits = 1; digits <= 17; ++digits) {
    const double candidate = std::strtod(StringPrintf("%.*g", digits, hz).c_str(), nullptr);
    if (HzToRadPerSecond(candidate) == omega_rad_s) return FormatRoundTrip(candidate);
  }
  return FormatRoundTrip(hz);
}

namespace {

// The optional columns the points carry.
struct OptionalColumns {
  bool phase = false;
  bool sigma = false;
  bool level_sigma = false;  // a_base_sigma
};

// Throws when a frequency sweep's dwells (one a_base, as the reader sees a
// sweep whose a_base never changes) state more than one a_base_sigma.
void CheckSharedLevelSigma(const Sweep& sweep) {
  for (const DwellPoint& point : sweep.points) {
    if (point.a_base != sweep.points.front().a_base) return;  // an amplitude sweep
  }
  for (const DwellPoint& point : sweep.points) {
    if (point.a_base_sigma == sweep.points.front().a_base_sigma) continue;
    throw InputError("sweep '" + sweep.Name() +
                     "' has one level a_base but dwells with different a_base_sigma; a frequency "
                     "sweep's dwells share one level and so one level error: give them the "
                     "same a_base_sigma");
  }
}

// Checks that the sweeps can be written and which optional columns they need:
// each is all or nothing.
OptionalColumns CheckSweeps(const std::vector<Sweep>& sweeps) {
  int with_sigma = 0;
  int with_phase = 0;
  int with_level_sigma = 0;
  int points = 0;
  for (const Sweep& sweep : sweeps) {
    if (sweep.id.empty() || sweep.id.find_first_of(",\"\r\n") != std::string::npos) {
      throw InputError("sweep id '" + sweep.id +
                       "' cannot be written as a CSV field; use non-empty plain text without "
                       "commas, quotes or line breaks");
    }
    for (const DwellPoint& point : sweep.points) {
      ++points;
      if (point.sigma.has_value()) ++with_sigma;
      if (point.phase_rad.has_value()) ++with_phase;
      if (point.a_base_sigma.has_value()) ++with_level_sigma;
    }
    CheckSharedLevelSigma(sweep);
  }
  for (const auto& [count, what] :
       {std::pair(with_sigma, "a sigma"), std::pair(with_phase, "a phase"),
        std::pair(with_level_sigma, "a level sigma (a_base_sigma)")}) {
    if (count != 0 && count != points) {
      throw InputError(std::to_string(count) + " of " + std::to_string(points) + " dwells carry " +
                       what + "; give every dwell " + what + " or none");
    }
  }
  return {with_phase > 0, with_sigma > 0, with_level_sigma > 0};
}

}  // namespace

void WriteSweepsCsv(const std::vector<Sweep>& sweeps, std::ostream* out) {
  const OptionalColumns columns = CheckSweeps(sweeps);
  *out << "sweep,direction,freq_hz,a_base,a" << (columns.phase ? ",phase_rad" : "")
       << (columns.sigma ? ",sigma" : "") << (columns.level_sigma ? ",a_base_sigma" : "") << "\n";
  for (const Sweep& sweep : sweeps) {
    const char* direction = SweepDirectionName(sweep.direction);
    for (const DwellPoint& point : sweep.points) {
      *out << sweep.id << ',' << direction << ',' << FormatFrequencyHz(point.drive_frequency_rad_s)
           << ',' << FormatRoundTrip(point.a_base) << ',' << FormatRoundTrip(point.amplitude);
      if (columns.phase) *out << ',' << FormatRoundTrip(*point.phase_rad);
      if (columns.sigma) *out << ',' << FormatRoundTrip(*point.sigma);
      if (columns.level_sigma) *out << ',' << FormatRoundTrip(*point.a_base_sigma);
      *out << '\n';
    }
  }
}

void WriteSweepsCsvFile(const std::vector<Sweep>& sweeps, const std::string& path) {
  std::ostringstream text;
  WriteSweepsCsv(sweeps, &text);
  WriteFileAtomically(text.str(), path);
}

void WriteFileAtomically(const std::string& text, const std::string& path) {
  // The process id keeps two runs into one folder from sharing a staged file.
  const std::string staged = path + ".partial." + std::to_string(::getpid());
  std::ofstream file(staged, std::ios::binary | std::ios::trunc);
  if (!file) {
    throw InputError(path, 0, "",
                     "cannot open the file for writing; check that its folder exists and is "
                     "writable");
  }
  file << text;
  file.close();
  std::error_code error;
  if (file) std::filesystem::rename(staged, path, error);
  if (!file || error) {
    std::filesystem::remove(staged, error);  // no half-written file is left behind
    throw InputError(path, 0, "",
                     "cannot write the file (disk full, a size limit, or the folder?)");
  }
}

}  // namespace dwellfit
