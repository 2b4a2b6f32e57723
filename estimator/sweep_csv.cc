#include "estimator/sweep_csv.h"

#include <glog/logging.h>
#include <libfccp/csv.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "estimator/input_error.h"
#include "residuals/model_parameters.h"

namespace dwellfit {
namespace {

constexpr char kSweepColumn[] = "sweep";
constexpr char kDirectionColumn[] = "direction";
constexpr char kFrequencyColumn[] = "freq_hz";
constexpr char kABaseColumn[] = "a_base";
constexpr char kAmplitudeColumn[] = "a";
constexpr char kPhaseDegColumn[] = "phase_deg";
constexpr char kPhaseRadColumn[] = "phase_rad";
constexpr char kSigmaColumn[] = "sigma";
constexpr int kNumColumns = 8;

constexpr char kAllowedColumns[] =
    "allowed columns are sweep, direction, freq_hz, a_base, a (required) and phase_deg or "
    "phase_rad, sigma (optional)";

constexpr double kRadiansPerDegree = kTwoPi / 360.0;

// Blank lines are skipped; fields are trimmed and may be double-quoted.
using CsvReader =
    io::CSVReader<kNumColumns, io::trim_chars<' ', '\t'>, io::double_quote_escape<',', '"'>,
                  io::throw_on_overflow, io::empty_line_comment>;

// One data row, as text; a column absent from the header stays nullptr.
struct RowFields {
  char* sweep = nullptr;
  char* direction = nullptr;
  char* freq_hz = nullptr;
  char* a_base = nullptr;
  char* a = nullptr;
  char* phase_deg = nullptr;
  char* phase_rad = nullptr;
  char* sigma = nullptr;
};

// Where in the file a value came from, for error messages.
struct Location {
  const std::string& file;
  int line;
};

// Parses the whole of `text` as a finite double, locale-independently.
double ParseNumber(const Location& where, const char* column, const char* text) {
  const char* begin = text;
  const char* end = text + std::strlen(text);
  if (begin == end) {
    throw InputError(where.file, where.line, column, "value is empty; expected a number");
  }
  if (*begin == '+' && end - begin > 1 && begin[1] != '-') ++begin;  // from_chars rejects '+'
  double value = 0.0;
  const auto [stop, error] = std::from_chars(begin, end, value);
  if (error == std::errc::result_out_of_range) {
    throw InputError(where.file, where.line, column,
                     "value '" + std::string(text) + "' is out of the range of a double");
  }
  if (error != std::errc() || stop != end) {
    throw InputError(where.file, where.line, column,
                     "value '" + std::string(text) + "' is not a number");
  }
  if (!std::isfinite(value)) {
    throw InputError(
        where.file, where.line, column,
        "value '" + std::string(text) +
            "' is not finite (NaN or infinity); give a measured number or drop the row");
  }
  return value;
}

double ParsePositive(const Location& where, const char* column, const char* text,
                     const char* meaning) {
  const double value = ParseNumber(where, column, text);
  if (!(value > 0.0)) {
    throw InputError(where.file, where.line, column,
                     std::string(meaning) + " must be > 0, got " + text);
  }
  return value;
}

// A drive frequency [Hz]: positive, and finite in rad/s too.
double ParseFrequencyHz(const Location& where, const char* text) {
  const double hz = ParsePositive(where, kFrequencyColumn, text, "the drive frequency");
  if (!std::isfinite(HzToRadPerSecond(hz))) {
    throw InputError(where.file, where.line, kFrequencyColumn,
                     "value '" + std::string(text) + "' is too large (infinite in rad/s)");
  }
  return hz;
}

// Reads the header and checks the column set; returns the header's line.
int ReadHeader(const std::string& path, CsvReader* reader) {
  try {
    reader->read_header(io::ignore_missing_column, kSweepColumn, kDirectionColumn, kFrequencyColumn,
                        kABaseColumn, kAmplitudeColumn, kPhaseDegColumn, kPhaseRadColumn,
                        kSigmaColumn);
  } catch (const io::error::header_missing&) {
    throw InputError(path, 1, "",
                     "the file is empty; expected a header row naming the columns (" +
                         std::string(kAllowedColumns) + ")");
  } catch (const io::error::extra_column_in_header& e) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), e.column_name,
                     std::string("unknown column; ") + kAllowedColumns);
  } catch (const io::error::duplicated_column_in_header& e) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), e.column_name,
                     "column appears twice in the header; keep one");
  } catch (const io::error::base& e) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     std::string("cannot read the header: ") + e.what());
  }
  const int header_line = static_cast<int>(reader->get_file_line());
  for (const char* column :
       {kSweepColumn, kDirectionColumn, kFrequencyColumn, kABaseColumn, kAmplitudeColumn}) {
    if (!reader->has_column(column)) {
      throw InputError(
          path, header_line, column,
          std::string("required column is missing from the header; ") + kAllowedColumns);
    }
  }
  if (reader->has_column(kPhaseDegColumn) && reader->has_column(kPhaseRadColumn)) {
    throw InputError(path, header_line, kPhaseRadColumn,
                     "the header has both phase_deg and phase_rad; keep one of them");
  }
  return header_line;
}

// Reads the next data row; false at the end of the file.
bool ReadRow(const std::string& path, CsvReader* reader, RowFields* row) {
  *row = RowFields();
  try {
    return reader->read_row(row->sweep, row->direction, row->freq_hz, row->a_base, row->a,
                            row->phase_deg, row->phase_rad, row->sigma);
  } catch (const io::error::too_few_columns&) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     "row has fewer fields than the header; give one value per header column");
  } catch (const io::error::too_many_columns&) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     "row has more fields than the header; give one value per header column");
  } catch (const io::error::escaped_string_not_closed&) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     "a quoted field is not closed; add the closing '\"'");
  } catch (const io::error::base& e) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     std::string("cannot read the row: ") + e.what());
  }
}

// One sweep being assembled, with what is needed to decide its kind.
struct SweepBuilder {
  Sweep sweep;
  int num_rows = 0;
  double first_freq_hz = 0.0;
  double first_a_base = 0.0;
  int freq_change_line = 0;    // first line whose freq_hz differs from the first row's
  int a_base_change_line = 0;  // likewise for a_base
};

// Records a row's controls; throws when the second control starts to vary.
void TrackControls(const Location& where, double freq_hz, double a_base, SweepBuilder* builder) {
  if (builder->num_rows++ == 0) {
    builder->first_freq_hz = freq_hz;
    builder->first_a_base = a_base;
    return;
  }
  if (builder->freq_change_line == 0 && freq_hz != builder->first_freq_hz) {
    builder->freq_change_line = where.line;
  }
  if (builder->a_base_change_line == 0 && a_base != builder->first_a_base) {
    builder->a_base_change_line = where.line;
  }
  if (builder->freq_change_line > 0 && builder->a_base_change_line > 0) {
    const bool a_base_second = builder->a_base_change_line >= builder->freq_change_line;
    throw InputError(
        where.file, where.line, a_base_second ? kABaseColumn : kFrequencyColumn,
        "sweep '" + builder->sweep.Name() + "' varies both freq_hz (first change at line " +
            std::to_string(builder->freq_change_line) + ") and a_base (first change at line " +
            std::to_string(builder->a_base_change_line) +
            "); a sweep varies one control only: give each setting of the other its own "
            "sweep id");
  }
}

void WarnAboutDroppedRows(const std::string& path, const std::vector<SweepBuilder>& builders) {
  for (const SweepBuilder& builder : builders) {
    const Sweep& sweep = builder.sweep;
    if (sweep.dropped_nonpositive == 0) continue;
    if (sweep.points.empty()) {
      LOG(WARNING) << path << ": sweep " << sweep.Name() << ": all " << builder.num_rows
                   << " rows have a <= 0 (missing measurements); the sweep is left out";
    } else {
      int trailing = 0;
      for (const MissingDwell& row : sweep.missing) {
        trailing += row.points_before == static_cast<int>(sweep.points.size());
      }
      LOG(WARNING) << path << ": sweep " << sweep.Name() << ": dropped "
                   << sweep.dropped_nonpositive << " of " << builder.num_rows
                   << " rows with a <= 0 (missing measurements"
                   << (trailing > 0 ? ", " + std::to_string(trailing) +
                                          " of them after the last "
                                          "measured row"
                                    : std::string())
                   << ")";
    }
  }
}

}  // namespace

LoadedSweeps LoadSweepsCsv(const std::string& path) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    throw InputError(path, 0, "", "is a directory; give the path of a sweeps CSV file");
  }
  std::optional<CsvReader> reader;
  try {
    reader.emplace(path);
  } catch (const io::error::can_not_open_file& e) {
    std::string reason = e.errno_value != 0 ? std::strerror(e.errno_value) : "unknown reason";
    throw InputError(path, 0, "",
                     "cannot open the file (" + reason + "); check the path and permissions");
  }
  const int header_line = ReadHeader(path, &*reader);
  const bool has_phase_deg = reader->has_column(kPhaseDegColumn);
  const bool has_phase_rad = reader->has_column(kPhaseRadColumn);
  const bool has_sigma = reader->has_column(kSigmaColumn);

  std::vector<SweepBuilder> builders;
  std::map<std::pair<std::string, SweepDirection>, size_t> index_of;
  RowFields row;
  while (ReadRow(path, &*reader, &row)) {
    const Location where{path, static_cast<int>(reader->get_file_line())};
    const std::string id = row.sweep;
    if (id.empty()) {
      throw InputError(path, where.line, kSweepColumn,
                       "sweep id is empty; give every row the id of its sweep");
    }
    SweepDirection direction;
    if (!SweepDirectionFromName(row.direction, &direction)) {
      throw InputError(path, where.line, kDirectionColumn,
                       "value '" + std::string(row.direction) + "' must be 'up' or 'down'");
    }
    const double freq_hz = ParseFrequencyHz(where, row.freq_hz);
    const double a_base = ParsePositive(where, kABaseColumn, row.a_base, "the base level a_base");
    const double amplitude = ParseNumber(where, kAmplitudeColumn, row.a);
    std::optional<double> phase_rad;
    if (has_phase_deg) {
      phase_rad = kRadiansPerDegree * ParseNumber(where, kPhaseDegColumn, row.phase_deg);
    } else if (has_phase_rad) {
      phase_rad = ParseNumber(where, kPhaseRadColumn, row.phase_rad);
    }
    std::optional<double> sigma;
    if (has_sigma) {
      sigma = ParsePositive(where, kSigmaColumn, row.sigma, "the standard deviation sigma");
    }

    const auto key = std::make_pair(id, direction);
    auto found = index_of.find(key);
    if (found == index_of.end()) {
      found = index_of.emplace(key, builders.size()).first;
      builders.emplace_back();
      builders.back().sweep.id = id;
      builders.back().sweep.direction = direction;
      builders.back().sweep.source_file = path;
    }
    SweepBuilder& builder = builders[found->second];
    TrackControls(where, freq_hz, a_base, &builder);
    if (!(amplitude > 0.0)) {
      ++builder.sweep.dropped_nonpositive;
      MissingDwell missing;
      missing.drive_frequency_rad_s = HzToRadPerSecond(freq_hz);
      missing.a_base = a_base;
      missing.points_before = static_cast<int>(builder.sweep.points.size());
      missing.source_line = where.line;
      builder.sweep.missing.push_back(missing);
      continue;
    }
    DwellPoint point;
    point.drive_frequency_rad_s = HzToRadPerSecond(freq_hz);
    point.a_base = a_base;
    point.amplitude = amplitude;
    point.phase_rad = phase_rad;
    point.sigma = sigma;
    point.source_line = where.line;
    builder.sweep.points.push_back(point);
  }
  if (builders.empty()) {
    throw InputError(path, header_line, "",
                     "the file has a header but no data rows; add one row per dwell");
  }

  WarnAboutDroppedRows(path, builders);
  LoadedSweeps loaded;
  for (SweepBuilder& builder : builders) {
    Sweep& sweep = builder.sweep;
    loaded.dropped_nonpositive += sweep.dropped_nonpositive;
    if (sweep.points.empty()) {
      loaded.all_dropped.push_back(sweep.Name());
      continue;
    }
    // Neither control varying (repeated dwells) counts as a frequency sweep.
    sweep.kind = builder.a_base_change_line > 0 ? SweepKind::kAmplitude : SweepKind::kFrequency;
    loaded.sweeps.push_back(std::move(sweep));
  }
  return loaded;
}

}  // namespace dwellfit
