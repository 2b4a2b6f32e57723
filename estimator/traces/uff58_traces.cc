#include "dwellfit/estimator/traces/uff58_traces.h"

#include <libfccp/csv.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/estimator/traces/uff58.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;

constexpr int kColumns = 8;
using IndexReader = io::CSVReader<kColumns, io::trim_chars<' ', '\t'>, io::no_quote_escape<','>,
                                  io::throw_on_overflow, io::empty_line_comment>;

// Where a dwell's field is, for the messages.
struct RowPlace {
  const std::string& index;
  int line;
};

// The UFF files read so far, by path.
using UffFiles = std::map<std::string, std::vector<Uff58Record>>;

// Whether `record` is the one `selector` (fid:N, node:N:D, id:TEXT) names.
bool Selects(const std::string& selector, const Uff58Record& record) {
  const auto whole = [](const std::string& text, long* value) {
    char* end = nullptr;
    *value = std::strtol(text.c_str(), &end, 10);
    return !text.empty() && *end == '\0';
  };
  long a = 0, b = 0;
  if (selector.rfind("fid:", 0) == 0) {
    return whole(selector.substr(4), &a) && a == record.function_id;
  }
  if (selector.rfind("node:", 0) == 0) {
    const std::string rest = selector.substr(5);
    const std::size_t colon = rest.find(':');
    return colon != std::string::npos && whole(rest.substr(0, colon), &a) &&
           whole(rest.substr(colon + 1), &b) && a == record.response_node &&
           b == record.response_direction;
  }
  std::string id = record.id_lines[0];
  id.erase(0, id.find_first_not_of(" \t"));
  return selector.rfind("id:", 0) == 0 && selector.substr(3) == id;
}

// The one data set 58 of `records` (of `file`) that `selector` names.
const Uff58Record& Select(const RowPlace& at, const char* field, const std::string& selector,
                          const std::string& file, const std::vector<Uff58Record>& records) {
  if (selector.rfind("fid:", 0) != 0 && selector.rfind("node:", 0) != 0 &&
      selector.rfind("id:", 0) != 0) {
    throw InputError(
        at.index, at.line, field,
        "expected fid:N, node:N:D or id:TEXT, got '" + EscapeForMessage(selector) + "'");
  }
  const Uff58Record* found = nullptr;
  for (const Uff58Record& record : records) {
    if (!Selects(selector, record)) continue;
    if (found != nullptr) {
      throw InputError(
          at.index, at.line, field,
          StringPrintf("'%s' names the data sets at lines %d and %d of %s; name one",
                       EscapeForMessage(selector).c_str(), found->line, record.line, file.c_str()));
    }
    found = &record;
  }
  if (found == nullptr) {
    throw InputError(at.index, at.line, field,
                     "no data set 58 of " + file + " is '" + EscapeForMessage(selector) + "'");
  }
  return *found;
}

// The samples of a channel, checked to be a time history in seconds with
// ordinate units `units`; its sample rate into `rate_hz`.
std::vector<float> Channel(const RowPlace& at, const char* field, const Uff58Record& r,
                           const std::string& file, const std::string& units, double* rate_hz) {
  const std::string set = StringPrintf("the data set 58 at line %d of %s", r.line, file.c_str());
  const auto fail = [&](const std::string& what) {
    throw InputError(at.index, at.line, field, set + " " + what);
  };
  if (!r.not_read.empty()) fail("has a " + r.not_read + "; give a real, evenly sampled channel");
  if (r.function_type != 0 && r.function_type != 1) {
    fail(StringPrintf("has function type %d; give a time response (1)", r.function_type));
  }
  if (!(r.abscissa.units == "s" ||
        (r.abscissa.units.empty() && r.abscissa.specific_data_type == 17))) {
    fail("has its abscissa in '" + EscapeForMessage(r.abscissa.units) +
         "'; give time histories whose abscissa is time in s");
  }
  if (!(r.abscissa_increment > 0.0) || r.values.empty()) {
    fail("has no samples or no positive abscissa increment");
  }
  if (r.ordinate.units != units) {
    fail("is in '" + EscapeForMessage(r.ordinate.units) + "' where this channel must be in '" +
         EscapeForMessage(units) + "' (base_unit for the base, V for the response)");
  }
  *rate_hz = SampleRateFromIncrement(r.abscissa_increment);
  for (std::size_t i = 0; i < r.values.size(); ++i) {
    if (std::abs(r.values[i]) > std::numeric_limits<float>::max()) {
      fail(StringPrintf("has value %zu = %g, beyond single precision; check the export", i + 1,
                        r.values[i]));
    }
  }
  return std::vector<float>(r.values.begin(), r.values.end());
}

// Dwell of index row `fields` (sweep, ..., base_unit).
DwellTrace ReadRow(const RowPlace& at, char* const* fields, UffFiles* files) {
  DwellTrace trace;
  trace.source_line = at.line;
  trace.source_file = at.index;
  ReadDwellColumns(at.index, at.line, fields, &trace);
  if (fields[4][0] == '\0') throw InputError(at.index, at.line, "file", "give the UFF file");
  const std::string file = (fs::path(at.index).parent_path() / fields[4]).string();
  auto cached = files->find(file);
  if (cached == files->end()) cached = files->emplace(file, ReadUff58File(file)).first;
  double base_hz = 0.0, response_hz = 0.0;
  trace.base = Channel(at, "base", Select(at, "base", fields[5], file, cached->second), file,
                       fields[7], &base_hz);
  trace.response = Channel(at, "response", Select(at, "response", fields[6], file, cached->second),
                           file, "V", &response_hz);
  if (base_hz != response_hz) {
    throw InputError(at.index, at.line, "response",
                     StringPrintf("is sampled at %.9g Hz, the base at %.9g Hz; give both channels "
                                  "of a dwell at one rate",
                                  response_hz, base_hz));
  }
  trace.sample_rate_hz = base_hz;
  return trace;
}

}  // namespace

double SampleRateFromIncrement(double increment_s) {
  const double rate_hz = 1.0 / increment_s;
  const double whole = std::round(rate_hz);
  return whole > 0.0 && std::abs(rate_hz - whole) <= 5e-6 * rate_hz ? whole : rate_hz;
}

std::vector<DwellTrace> ReadUffTraceSet(const std::string& index_path) {
  std::error_code error;
  if (!fs::is_regular_file(index_path, error)) {
    throw InputError(index_path, 0, "", "is not a readable file; give the UFF index (a CSV file)");
  }
  std::vector<DwellTrace> dwells;
  UffFiles files;
  try {
    IndexReader reader(index_path);
    reader.read_header(io::ignore_no_column, "sweep", "direction", "kind", "freq_hz", "file",
                       "base", "response", "base_unit");
    char* fields[kColumns] = {};
    while (reader.read_row(fields[0], fields[1], fields[2], fields[3], fields[4], fields[5],
                           fields[6], fields[7])) {
      const RowPlace at{index_path, static_cast<int>(reader.get_file_line())};
      dwells.push_back(ReadRow(at, fields, &files));
    }
  } catch (const io::error::base& e) {
    throw InputError(index_path, 0, "",
                     std::string("cannot read the UFF index (columns sweep, direction, kind, "
                                 "freq_hz, file, base, response, base_unit): ") +
                         e.what());
  }
  if (dwells.empty()) throw InputError(index_path, 0, "", "the UFF index lists no dwell");
  return dwells;
}

namespace {

// A data set 58 of one channel of `dwell`.
Uff58Record ChannelRecord(const DwellTrace& dwell, const std::vector<float>& samples, int id,
                          const std::string& what, const std::string& units, bool binary) {
  Uff58Record r;
  r.id_lines[0] = dwell.sweep + "/" + SweepDirectionName(dwell.direction) + " " +
                  FormatFrequencyHz(dwell.drive_frequency_rad_s) + " Hz " + what;
  r.id_lines[1] = "dwellfit virtual rig";
  r.function_type = 1;
  r.function_id = id;
  r.response_entity = what;
  r.response_node = id;
  r.ordinate_data_type = binary ? 2 : 4;
  r.value_count = static_cast<std::int64_t>(samples.size());
  r.abscissa_increment = 1.0 / dwell.sample_rate_hz;
  r.abscissa = {17, 0, 0, 0, "Time", "s"};
  r.ordinate = {what == "base" ? 12 : 1, 0, 0, 0, what, units};
  r.values.assign(samples.begin(), samples.end());
  return r;
}

void WriteFile(const std::string& text, const std::string& path) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << text;
  file.close();
  if (!file) throw InputError(path, 0, "", "cannot write the file; check its folder");
}

}  // namespace

void WriteUffTraceSet(const std::vector<DwellTrace>& dwells, const std::string& uff_path,
                      const std::string& index_path, bool binary, const std::string& base_unit) {
  std::string uff;
  std::string index = "sweep,direction,kind,freq_hz,file,base,response,base_unit\n";
  const std::string name = fs::path(uff_path).filename().string();
  int id = 0;
  for (const DwellTrace& dwell : dwells) {
    AppendUff58(ChannelRecord(dwell, dwell.base, ++id, "base", base_unit, binary), binary, &uff);
    AppendUff58(ChannelRecord(dwell, dwell.response, ++id, "response", "V", binary), binary, &uff);
    index += dwell.sweep + "," + SweepDirectionName(dwell.direction) + "," +
             SweepKindName(dwell.kind) + "," + FormatFrequencyHz(dwell.drive_frequency_rad_s) +
             "," + name + StringPrintf(",fid:%d,fid:%d,", id - 1, id) + base_unit + "\n";
  }
  WriteFile(uff, uff_path);
  WriteFile(index, index_path);
}

}  // namespace dwellfit
