#include "dwellfit/estimator/data/sweep_csv.h"

#include <glog/logging.h>
#include <libfccp/csv.h>

#include <algorithm>
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

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/residuals/model/model_parameters.h"

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
constexpr char kABaseSigmaColumn[] = "a_base_sigma";
constexpr int kNumColumns = 9;

constexpr char kAllowedColumns[] =
    "allowed columns are sweep, direction, freq_hz, a_base, a (required) and phase_deg or "
    "phase_rad, sigma, a_base_sigma (optional)";

constexpr double kRadiansPerDegree = kTwoPi / 360.0;

// Blank lines are skipped; fields are trimmed and may be double-quoted.
using CsvReader =
    io::CSVReader<kNumColumns, io::trim_chars<' ', '\t'>, io::double_quote_escape<',', '"'>,
                  io::throw_on_overflow, io::empty_line_comment>;

// One data row, as text; a column absent from the header stays nullptr.
using RowFields = SweepRowFields;

// Where in the file a value came from, for error messages.
struct Location {
  const std::string& file;
  int line;
};

// The accepted values of a column (see the header for why these bounds).
struct Range {
  double min;
  double max;
  const char* meaning;  // "the drive frequency"
  const char* power;    // the highest power the model takes of it
  const char* advice;   // what a value outside the range usually means
};

const Range kFrequencyRange = {1e-6, 1e9, "the drive frequency [Hz]", "Omega^4",
                               "freq_hz is in Hz (not rad/s or kHz)"};
const Range kABaseRange = {1e-20, 1e20, "the base level a_base", "a_base^2",
                           "give a_base in a unit that puts it inside the range"};
const Range kAmplitudeRange = {
    1e-20, 1e20, "the amplitude a", "a^6",
    "give a in a unit that puts it inside the range, or write 0 for a missing measurement"};
const Range kSigmaRange = {1e-20, 1e20, "the standard deviation sigma", "sigma^2",
                           "sigma is in the unit of a"};
const Range kABaseSigmaRange = {1e-20, 1e20, "the standard deviation a_base_sigma",
                                "a_base_sigma^2", "a_base_sigma is in the unit of a_base"};

// Parses the whole of `text` as a finite double, locale-independently.
double ParseNumber(const Location& where, const char* column, const char* text) {
  const char* begin = text;
  const char* end = text + std::strlen(text);
  if (begin == end) {
    throw InputError(where.file, where.line, column, "value is empty; expected a number");
  }
  // Only an error message shows the value (built then, not for every number).
  auto shown = [text] { return "value '" + EscapeForMessage(text) + "'"; };
  if (*begin == '+' && end - begin > 1 && begin[1] != '-') ++begin;  // from_chars rejects '+'
  double value = 0.0;
  const auto [stop, error] = std::from_chars(begin, end, value);
  if (error == std::errc::result_out_of_range) {
    throw InputError(where.file, where.line, column, shown() + " is out of the range of a double");
  }
  if (error != std::errc() || stop != end) {
    const bool comma = std::strchr(text, ',') != nullptr;
    throw InputError(where.file, where.line, column,
                     shown() + " is not a number" +
                         (comma ? "; write numbers with a decimal point, not a comma (40.5, "
                                  "not 40,5)"
                                : ""));
  }
  if (!std::isfinite(value)) {
    throw InputError(where.file, where.line, column,
                     shown() +
                         " is not finite (NaN or infinity); give a measured number or drop "
                         "the row");
  }
  return value;
}

// A number > 0 inside `range`.
double ParseInRange(const Location& where, const char* column, const char* text,
                    const Range& range) {
  const double value = ParseNumber(where, column, text);
  if (!(value > 0.0)) {
    throw InputError(where.file, where.line, column,
                     std::string(range.meaning) + " must be > 0, got " + EscapeForMessage(text));
  }
  if (value < range.min || value > range.max) {
    throw InputError(where.file, where.line, column,
                     std::string(range.meaning) + " " + EscapeForMessage(text) +
                         " is outside the accepted range [" + FormatRoundTrip(range.min) + ", " +
                         FormatRoundTrip(range.max) + "], beyond which the model's powers (" +
                         range.power + ") and squared residuals overflow or underflow; " +
                         range.advice);
  }
  return value;
}

// What an unknown column's name suggests went wrong, as advice.
std::string UnknownColumnAdvice(const std::string& name) {
  if (name.find(';') != std::string::npos || name.find('\t') != std::string::npos) {
    const char* separator = name.find(';') != std::string::npos ? "';'" : "tabs";
    return std::string(
               "; the header reads as one column: this file seems to separate fields "
               "by ") +
           separator +
           ", but a sweeps CSV separates them by commas (and writes numbers with a '.' decimal "
           "point): save it as comma-separated";
  }
  if (name.find('\r') != std::string::npos) {
    return "; the lines of this file end in a carriage return alone (\\r, old Mac style): save "
           "it with LF or CRLF line ends";
  }
  return "; the first line must be the header naming the columns";
}

// The message of a line longer than the reader's limit.
std::string LineTooLong() {
  return "the line is longer than 2^24 - 1 bytes, which no row of a sweeps CSV is; check that "
         "this is the sweeps file";
}

// Reads the header and checks the column set; returns the header's line.
int ReadHeader(const std::string& path, CsvReader* reader) {
  try {
    reader->read_header(io::ignore_missing_column, kSweepColumn, kDirectionColumn, kFrequencyColumn,
                        kABaseColumn, kAmplitudeColumn, kPhaseDegColumn, kPhaseRadColumn,
                        kSigmaColumn, kABaseSigmaColumn);
  } catch (const io::error::header_missing&) {
    throw InputError(path, 1, "",
                     "the file is empty; expected a header row naming the columns (" +
                         std::string(kAllowedColumns) + ")");
  } catch (const io::error::extra_column_in_header& e) {
    throw InputError(
        path, static_cast<int>(reader->get_file_line()), EscapeForMessage(e.column_name),
        std::string("unknown column; ") + kAllowedColumns + UnknownColumnAdvice(e.column_name));
  } catch (const io::error::duplicated_column_in_header& e) {
    throw InputError(path, static_cast<int>(reader->get_file_line()),
                     EscapeForMessage(e.column_name),
                     "column appears twice in the header; keep one");
  } catch (const io::error::line_length_limit_exceeded& e) {
    throw InputError(path, static_cast<int>(e.file_line), "", LineTooLong());
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
                            row->phase_deg, row->phase_rad, row->sigma, row->a_base_sigma);
  } catch (const io::error::too_few_columns&) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     "row has fewer fields than the header; give one value per header column");
  } catch (const io::error::too_many_columns&) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     "row has more fields than the header; give one value per header column "
                     "(a decimal comma splits a number in two: write 40.5, not 40,5)");
  } catch (const io::error::escaped_string_not_closed&) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     "a quoted field is not closed; add the closing '\"'");
  } catch (const io::error::line_length_limit_exceeded& e) {
    throw InputError(path, static_cast<int>(e.file_line), "", LineTooLong());
  } catch (const io::error::base& e) {
    throw InputError(path, static_cast<int>(reader->get_file_line()), "",
                     std::string("cannot read the row: ") + e.what());
  }
}

// One row's values, parsed and checked one by one.
struct RowValues {
  int line = 0;
  std::string id;
  SweepDirection direction = SweepDirection::kUp;
  double freq_hz = 0.0;
  double a_base = 0.0;
  double amplitude = 0.0;  // <= 0: a missing measurement
  std::optional<double> phase_rad;
  std::optional<double> sigma;
  std::optional<double> a_base_sigma;  // standard deviation of a_base (a_base's unit)
};

RowValues ParseRow(const Location& where, const RowFields& row) {
  RowValues values;
  values.line = where.line;
  values.id = row.sweep;
  if (values.id.empty()) {
    throw InputError(where.file, where.line, kSweepColumn,
                     "sweep id is empty; give every row the id of its sweep");
  }
  if (!SweepDirectionFromName(row.direction, &values.direction)) {
    throw InputError(where.file, where.line, kDirectionColumn,
                     "value '" + EscapeForMessage(row.direction) + "' must be 'up' or 'down'");
  }
  values.freq_hz = ParseInRange(where, kFrequencyColumn, row.freq_hz, kFrequencyRange);
  values.a_base = ParseInRange(where, kABaseColumn, row.a_base, kABaseRange);
  values.amplitude = ParseNumber(where, kAmplitudeColumn, row.a);
  if (values.amplitude > 0.0) {
    values.amplitude = ParseInRange(where, kAmplitudeColumn, row.a, kAmplitudeRange);
  }
  if (row.phase_deg != nullptr) {
    values.phase_rad = kRadiansPerDegree * ParseNumber(where, kPhaseDegColumn, row.phase_deg);
  } else if (row.phase_rad != nullptr) {
    values.phase_rad = ParseNumber(where, kPhaseRadColumn, row.phase_rad);
  }
  if (row.sigma != nullptr)
    values.sigma = ParseInRange(where, kSigmaColumn, row.sigma, kSigmaRange);
  if (row.a_base_sigma != nullptr) {
    values.a_base_sigma =
        ParseInRange(where, kABaseSigmaColumn, row.a_base_sigma, kABaseSigmaRange);
  }
  return values;
}

// One sweep being assembled, with what is needed to decide its kind.
struct SweepBuilder {
  Sweep sweep;
  int num_rows = 0;
  double first_freq_hz = 0.0;
  double first_a_base = 0.0;
  int freq_change_line = 0;    // first line whose freq_hz differs from the first row's
  int a_base_change_line = 0;  // likewise for a_base
  RowValues first;             // the sweep's first row
  // The first line whose a_base_sigma differs from the first row's (0: none
  // yet), and its value.
  int a_base_sigma_change_line = 0;
  std::optional<double> changed_a_base_sigma;
  RowValues last;  // the sweep's previous row
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
    throw InputError(where.file, where.line, a_base_second ? kABaseColumn : kFrequencyColumn,
                     "sweep '" + EscapeForMessage(builder->sweep.Name()) +
                         "' varies both freq_hz (first change at line " +
                         std::to_string(builder->freq_change_line) +
                         ") and a_base (first change at line " +
                         std::to_string(builder->a_base_change_line) +
                         "); a sweep varies one control only: give each setting of the other "
                         "its own sweep id");
  }
}

// Text of an optional a_base_sigma for messages.
std::string LevelSigmaText(const std::optional<double>& sigma) {
  return sigma ? FormatRoundTrip(*sigma) : std::string("none");
}

// Throws when the frequency sweep (one level a_base) of `builder` states two
// values of a_base_sigma, naming the first row whose value differs.
void CheckSharedLevelSigma(const std::string& path, const SweepBuilder& builder) {
  if (builder.a_base_sigma_change_line == 0) return;
  throw InputError(
      path, builder.a_base_sigma_change_line, kABaseSigmaColumn,
      "sweep '" + EscapeForMessage(builder.sweep.Name()) +
          "' is a frequency sweep (one level a_base), but its a_base_sigma changes from " +
          LevelSigmaText(builder.first.a_base_sigma) + " (line " +
          std::to_string(builder.first.line) + ") to " +
          LevelSigmaText(builder.changed_a_base_sigma) +
          "; the rows of a frequency sweep share one level and so one level error: give each "
          "of them the same a_base_sigma (the standard deviation of the sweep's level)");
}

// Records where a row's a_base_sigma first differs from its sweep's first
// row's; throws once freq_hz varies too (the sweep is a frequency sweep).
void TrackLevelSigma(const Location& where, const RowValues& row, SweepBuilder* builder) {
  if (builder->num_rows == 1) {
    builder->first = row;
    return;
  }
  if (builder->a_base_sigma_change_line == 0 && row.a_base_sigma != builder->first.a_base_sigma) {
    builder->a_base_sigma_change_line = where.line;
    builder->changed_a_base_sigma = row.a_base_sigma;
  }
  if (builder->freq_change_line > 0) CheckSharedLevelSigma(where.file, *builder);
}

// Throws when `row` moves its sweep's control against the sweep's direction
// (a frequency sweep's freq_hz, an amplitude sweep's a_base; only one varies).
void CheckOrder(const Location& where, const RowValues& row, const SweepBuilder& builder) {
  const RowValues& last = builder.last;
  const bool frequency = row.freq_hz != last.freq_hz;
  const double before = frequency ? last.freq_hz : last.a_base;
  const double now = frequency ? row.freq_hz : row.a_base;
  const bool up = row.direction == SweepDirection::kUp;
  if (up ? now >= before : now <= before) return;
  const char* column = frequency ? kFrequencyColumn : kABaseColumn;
  throw InputError(
      where.file, where.line, column,
      "sweep '" + EscapeForMessage(builder.sweep.Name()) + "' is " + (up ? "an up" : "a down") +
          "-sweep, but " + column + (up ? " falls" : " rises") + " from " +
          FormatRoundTrip(before) + " (line " + std::to_string(last.line) + ") to " +
          FormatRoundTrip(now) +
          "; rows must be in measurement order, the control rising in an up-sweep and falling in "
          "a down-sweep (repeats allowed). The order places the jumps, so it is not repaired: "
          "restore the measured order (a shuffled, reversed or twice-appended file shows this), "
          "or give a second pass its own sweep id");
}

// Throws when `row` repeats its sweep's previous row value for value.
void CheckNotACopy(const Location& where, const RowValues& row, const SweepBuilder& builder) {
  const RowValues& last = builder.last;
  if (!(row.amplitude > 0.0) || row.amplitude != last.amplitude || row.freq_hz != last.freq_hz ||
      row.a_base != last.a_base || row.phase_rad != last.phase_rad || row.sigma != last.sigma ||
      row.a_base_sigma != last.a_base_sigma) {
    return;
  }
  throw InputError(where.file, where.line, "",
                   "row repeats line " + std::to_string(last.line) + " value for value (sweep '" +
                       EscapeForMessage(builder.sweep.Name()) +
                       "'): a copied row counts one dwell twice and understates the "
                       "uncertainty; remove it (a dwell measured again gives its own reading; "
                       "if two readings really agree, keep one row)");
}

// Adds a checked row to its sweep: a dwell, or a missing measurement (a <= 0).
void AddRow(const Location& where, const RowValues& row, SweepBuilder* builder) {
  TrackControls(where, row.freq_hz, row.a_base, builder);
  TrackLevelSigma(where, row, builder);
  if (builder->num_rows > 1) {
    CheckOrder(where, row, *builder);
    CheckNotACopy(where, row, *builder);
  }
  builder->last = row;
  Sweep& sweep = builder->sweep;
  if (!(row.amplitude > 0.0)) {
    ++sweep.dropped_nonpositive;
    sweep.missing.push_back(MissingDwell{HzToRadPerSecond(row.freq_hz), row.a_base,
                                         static_cast<int>(sweep.points.size()), row.line});
    return;
  }
  sweep.points.push_back(DwellPoint{HzToRadPerSecond(row.freq_hz), row.a_base, row.amplitude,
                                    row.phase_rad, row.sigma, Branch::kOnly, row.line,
                                    row.a_base_sigma});
}

void WarnAboutDroppedRows(const std::string& path, const std::vector<SweepBuilder>& builders) {
  for (const SweepBuilder& builder : builders) {
    const Sweep& sweep = builder.sweep;
    if (sweep.dropped_nonpositive == 0) continue;
    if (sweep.points.empty()) {
      LOG(WARNING) << path << ": sweep " << sweep.Name() << ": all " << builder.num_rows
                   << " rows have a <= 0 (missing measurements); the sweep is left out";
    } else {
      const auto trailing =
          std::count_if(sweep.missing.begin(), sweep.missing.end(), [&](const MissingDwell& row) {
            return row.points_before == static_cast<int>(sweep.points.size());
          });
      LOG(WARNING) << path << ": sweep " << sweep.Name() << ": dropped "
                   << sweep.dropped_nonpositive << " of " << builder.num_rows
                   << " rows with a <= 0 (missing measurements"
                   << (trailing > 0 ? ", " + std::to_string(trailing) +
                                          " of them after the last measured row"
                                    : "")
                   << ")";
    }
  }
}

// Opens `path` for reading; throws InputError when it is no readable file.
void OpenCsv(const std::string& path, std::optional<CsvReader>* reader) {
  const std::string not_a_file = NotARegularFile(path);
  if (!not_a_file.empty()) {
    throw InputError(path, 0, "", not_a_file + "; give the path of a sweeps CSV file");
  }
  try {
    reader->emplace(path);
  } catch (const io::error::can_not_open_file& e) {
    std::string reason = e.errno_value != 0 ? std::strerror(e.errno_value) : "unknown reason";
    throw InputError(path, 0, "",
                     "cannot open the file (" + reason + "); check the path and permissions");
  }
}

// The loaded sweeps, in order of first appearance, less those without a dwell.
LoadedSweeps Collect(std::vector<SweepBuilder>* builders) {
  LoadedSweeps loaded;
  for (SweepBuilder& builder : *builders) {
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

}  // namespace

std::string NotARegularFile(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status) || std::filesystem::is_regular_file(status)) {
    return "";
  }
  using Type = std::filesystem::file_type;
  const Type type = status.type();
  if (type == Type::directory) return "is a directory";
  if (type == Type::character) return "is a character device, not a file";
  if (type == Type::block) return "is a block device, not a file";
  if (type == Type::fifo) return "is a named pipe (FIFO), not a file";
  if (type == Type::socket) return "is a socket, not a file";
  return "is not a regular file";
}

LoadedSweeps LoadSweepsCsv(const std::string& path) {
  std::optional<CsvReader> reader;
  OpenCsv(path, &reader);
  const int header_line = ReadHeader(path, &*reader);
  return LoadSweepsFromRows(path, header_line, [&](RowFields* fields, int* line) {
    if (!ReadRow(path, &*reader, fields)) return false;
    *line = static_cast<int>(reader->get_file_line());
    return true;
  });
}

LoadedSweeps LoadSweepsFromRows(const std::string& path, int header_line,
                                const SweepRowSource& next_row) {
  std::vector<SweepBuilder> builders;
  std::map<std::pair<std::string, SweepDirection>, size_t> index_of;
  std::size_t current = 0;  // the previous row's sweep in `builders`
  RowFields fields;
  int line = 0;
  while (next_row(&fields, &line)) {
    const Location where{path, line};
    const RowValues row = ParseRow(where, fields);
    // Rows come sweep by sweep: most belong to the previous row's sweep.
    const bool same_sweep = current < builders.size() && builders[current].sweep.id == row.id &&
                            builders[current].sweep.direction == row.direction;
    if (!same_sweep) {
      const auto [found, inserted] =
          index_of.emplace(std::make_pair(row.id, row.direction), builders.size());
      if (inserted) {
        builders.emplace_back();
        builders.back().sweep.id = row.id;
        builders.back().sweep.direction = row.direction;
        builders.back().sweep.source_file = path;
      }
      current = found->second;
    }
    AddRow(where, row, &builders[current]);
  }
  if (builders.empty()) {
    throw InputError(path, header_line, "",
                     "the file has a header but no data rows; add one row per dwell");
  }
  // A sweep whose controls never varied is a frequency sweep too.
  for (const SweepBuilder& builder : builders) {
    if (builder.a_base_change_line == 0) CheckSharedLevelSigma(path, builder);
  }
  WarnAboutDroppedRows(path, builders);
  return Collect(&builders);
}

}  // namespace dwellfit
