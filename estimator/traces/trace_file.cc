#include "dwellfit/estimator/traces/trace_file.h"

#include <libfccp/csv.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;

constexpr int kIndexColumns = 7;
using IndexReader =
    io::CSVReader<kIndexColumns, io::trim_chars<' ', '\t'>, io::no_quote_escape<','>,
                  io::throw_on_overflow, io::empty_line_comment>;

// A little-endian float32 from/to 4 bytes, whatever the host's byte order.
void PutFloat(float value, std::string* out) {
  std::uint32_t bits;
  static_assert(sizeof(bits) == sizeof(value), "float32");
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((bits >> (8 * i)) & 0xFF));
}

float GetFloat(const unsigned char* bytes) {
  std::uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) bits |= static_cast<std::uint32_t>(bytes[i]) << (8 * i);
  float value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

// Writes `text` to `path` through a temporary file renamed into place.
void WriteAtomically(const std::string& text, const fs::path& path) {
  const fs::path staged = path.string() + ".partial";
  {
    std::ofstream file(staged, std::ios::binary | std::ios::trunc);
    if (!file) {
      throw InputError(staged.string(), 0, "",
                       "cannot open the file for writing; check that the folder is writable");
    }
    file << text;
    file.close();
    if (!file) throw InputError(staged.string(), 0, "", "writing the file failed (disk full?)");
  }
  std::error_code error;
  fs::rename(staged, path, error);
  if (error) throw InputError(path.string(), 0, "", "cannot rename into place: " + error.message());
}

double ParsePositive(const std::string& file, int line, const char* field, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(value) || !(value > 0.0)) {
    throw InputError(file, line, field,
                     "expected a positive number, got '" + EscapeForMessage(text) + "'");
  }
  return value;
}

long ParseCount(const std::string& file, int line, const char* field, const char* text) {
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || value < 0 || value > (1L << 30)) {
    throw InputError(file, line, field,
                     "expected a whole number of samples, got '" + EscapeForMessage(text) + "'");
  }
  return value;
}

// One index row into `trace` (samples not yet read).
DwellTrace ReadIndexRow(const std::string& file, int line, char* const* fields) {
  DwellTrace trace;
  trace.source_line = line;
  trace.sweep = fields[0];
  if (trace.sweep.empty()) throw InputError(file, line, "sweep", "give the sweep id");
  if (!SweepDirectionFromName(fields[1], &trace.direction)) {
    throw InputError(file, line, "direction",
                     "expected up or down, got '" + EscapeForMessage(fields[1]) + "'");
  }
  const std::string kind = fields[2];
  if (kind == SweepKindName(SweepKind::kFrequency)) {
    trace.kind = SweepKind::kFrequency;
  } else if (kind == SweepKindName(SweepKind::kAmplitude)) {
    trace.kind = SweepKind::kAmplitude;
  } else {
    throw InputError(file, line, "kind",
                     "expected frequency or amplitude, got '" + EscapeForMessage(kind) + "'");
  }
  trace.drive_frequency_rad_s = HzToRadPerSecond(ParsePositive(file, line, "freq_hz", fields[3]));
  trace.sample_rate_hz = ParsePositive(file, line, "sample_rate_hz", fields[4]);
  trace.base.resize(ParseCount(file, line, "base_samples", fields[5]));
  trace.response.resize(ParseCount(file, line, "response_samples", fields[6]));
  return trace;
}

std::vector<DwellTrace> ReadIndex(const std::string& path) {
  std::vector<DwellTrace> dwells;
  try {
    IndexReader reader(path);
    reader.read_header(io::ignore_no_column, "sweep", "direction", "kind", "freq_hz",
                       "sample_rate_hz", "base_samples", "response_samples");
    char* fields[kIndexColumns] = {};
    while (reader.read_row(fields[0], fields[1], fields[2], fields[3], fields[4], fields[5],
                           fields[6])) {
      // read_header has checked that every column is there: no field is null.
      dwells.push_back(ReadIndexRow(path, static_cast<int>(reader.get_file_line()), fields));
    }
  } catch (const io::error::base& e) {
    throw InputError(path, 0, "", std::string("cannot read the trace index: ") + e.what());
  }
  if (dwells.empty()) throw InputError(path, 0, "", "the trace index lists no dwell");
  return dwells;
}

}  // namespace

std::string DwellTrace::Describe() const {
  std::string text = sweep + "/" + SweepDirectionName(direction) + " @ " +
                     FormatFrequencyHz(drive_frequency_rad_s) + " Hz";
  if (source_line > 0) text += StringPrintf(" (%s:%d)", kTraceIndexFile, source_line);
  return text;
}

void WriteTraceSet(const std::vector<DwellTrace>& dwells, const std::string& folder) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) throw InputError(folder, 0, "", "cannot create the folder: " + error.message());
  std::ostringstream index;
  index << "sweep,direction,kind,freq_hz,sample_rate_hz,base_samples,response_samples\n";
  std::string samples;
  for (const DwellTrace& dwell : dwells) {
    if (dwell.sweep.empty() || dwell.sweep.find_first_of(",\"\r\n") != std::string::npos) {
      throw InputError("sweep id '" + EscapeForMessage(dwell.sweep) +
                       "' cannot be written as a CSV field");
    }
    index << dwell.sweep << ',' << SweepDirectionName(dwell.direction) << ','
          << SweepKindName(dwell.kind) << ',' << FormatFrequencyHz(dwell.drive_frequency_rad_s)
          << ',' << FormatRoundTrip(dwell.sample_rate_hz) << ',' << dwell.base.size() << ','
          << dwell.response.size() << '\n';
    for (float value : dwell.base) PutFloat(value, &samples);
    for (float value : dwell.response) PutFloat(value, &samples);
  }
  WriteAtomically(samples, fs::path(folder) / kTraceSamplesFile);
  WriteAtomically(index.str(), fs::path(folder) / kTraceIndexFile);
}

std::vector<DwellTrace> ReadTraceSet(const std::string& folder) {
  const std::string index_path = (fs::path(folder) / kTraceIndexFile).string();
  const std::string samples_path = (fs::path(folder) / kTraceSamplesFile).string();
  std::vector<DwellTrace> dwells = ReadIndex(index_path);
  std::ifstream file(samples_path, std::ios::binary);
  if (!file) throw InputError(samples_path, 0, "", "cannot open the samples file");
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::size_t expected = 0;
  for (const DwellTrace& dwell : dwells)
    expected += 4 * (dwell.base.size() + dwell.response.size());
  if (bytes.size() != expected) {
    throw InputError(samples_path, 0, "",
                     StringPrintf("holds %zu bytes, but %s announces %zu (4 per sample); the two "
                                  "files do not belong together or one was cut short",
                                  bytes.size(), kTraceIndexFile, expected));
  }
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  for (DwellTrace& dwell : dwells) {
    for (float& value : dwell.base) value = GetFloat(data), data += 4;
    for (float& value : dwell.response) value = GetFloat(data), data += 4;
  }
  return dwells;
}

}  // namespace dwellfit
