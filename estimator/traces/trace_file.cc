#include "dwellfit/estimator/traces/trace_file.h"

#include <libfccp/csv.h>

#include <boost/crc.hpp>
#include <boost/endian/conversion.hpp>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/residuals/model/model_parameters.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;

constexpr int kIndexColumns = 8;
using IndexReader =
    io::CSVReader<kIndexColumns, io::trim_chars<' ', '\t'>, io::no_quote_escape<','>,
                  io::throw_on_overflow, io::empty_line_comment>;

// A dwell's index row: the trace without its samples, their counts, and the
// CRC-32 of its samples' bytes (none in a set written before the column).
struct IndexRow {
  DwellTrace trace;
  std::uint64_t base_samples = 0;
  std::uint64_t response_samples = 0;
  std::optional<std::uint32_t> crc32;
};

// The CRC-32 (boost::crc_32_type) of `size` bytes.
std::uint32_t Crc32(const void* bytes, std::size_t size) {
  boost::crc_32_type crc;
  crc.process_bytes(bytes, size);
  return crc.checksum();
}

// Throws InputError unless `path` is a regular file (not a folder, a device
// such as /dev/zero, or a pipe that would block the read).
void RequireRegularFile(const std::string& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    throw InputError(path, 0, "",
                     fs::exists(path, error)
                         ? "is not a regular file (a folder, device or pipe); give the file itself"
                         : "cannot open the file; check the path");
  }
}

// A float32 as 4 little-endian bytes, whatever the host's byte order.
void PutFloat(float value, std::string* out) {
  unsigned char bytes[4];
  boost::endian::endian_store<float, 4, boost::endian::order::little>(bytes, value);
  out->append(reinterpret_cast<const char*>(bytes), 4);
}

double ParsePositive(const std::string& file, int line, const char* field, const char* text) {
  // Decimal notation only: strtod alone would take "0x28" as 40.
  const bool decimal = std::strspn(text, "0123456789+-.eE") == std::strlen(text);
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (!decimal || end == text || *end != '\0' || !std::isfinite(value) || !(value > 0.0)) {
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

// One index row (samples not yet read).
IndexRow ReadIndexRow(const std::string& file, int line, char* const* fields) {
  IndexRow row;
  DwellTrace& trace = row.trace;
  trace.source_line = line;
  ReadDwellColumns(file, line, fields, &trace);
  trace.sample_rate_hz = ParsePositive(file, line, "sample_rate_hz", fields[4]);
  row.base_samples = ParseCount(file, line, "base_samples", fields[5]);
  row.response_samples = ParseCount(file, line, "response_samples", fields[6]);
  if (fields[7] != nullptr) {
    char* end = nullptr;
    const unsigned long long crc = std::strtoull(fields[7], &end, 16);
    if (end == fields[7] || *end != '\0' || crc > 0xFFFFFFFFull) {
      throw InputError(file, line, "samples_crc32",
                       "expected 8 hexadecimal digits, got '" + EscapeForMessage(fields[7]) + "'");
    }
    row.crc32 = static_cast<std::uint32_t>(crc);
  }
  return row;
}

std::vector<IndexRow> ReadIndex(const std::string& path) {
  RequireRegularFile(path);
  std::vector<IndexRow> dwells;
  try {
    IndexReader reader(path);
    reader.read_header(io::ignore_missing_column, "sweep", "direction", "kind", "freq_hz",
                       "sample_rate_hz", "base_samples", "response_samples", "samples_crc32");
    char* fields[kIndexColumns] = {};
    while (reader.read_row(fields[0], fields[1], fields[2], fields[3], fields[4], fields[5],
                           fields[6], fields[7])) {
      for (int i = 0; i + 1 < kIndexColumns; ++i) {
        if (fields[i] == nullptr) {
          throw InputError(path, static_cast<int>(reader.get_file_line()), "",
                           "the header lacks a column; expected sweep, direction, kind, freq_hz, "
                           "sample_rate_hz, base_samples, response_samples");
        }
      }
      dwells.push_back(ReadIndexRow(path, static_cast<int>(reader.get_file_line()), fields));
    }
  } catch (const io::error::base& e) {
    throw InputError(path, 0, "", std::string("cannot read the trace index: ") + e.what());
  }
  if (dwells.empty()) throw InputError(path, 0, "", "the trace index lists no dwell");
  return dwells;
}

}  // namespace

void ReadDwellColumns(const std::string& file, int line, const char* const* fields,
                      DwellTrace* trace) {
  trace->sweep = fields[0];
  if (trace->sweep.empty()) throw InputError(file, line, "sweep", "give the sweep id");
  if (!SweepDirectionFromName(fields[1], &trace->direction)) {
    throw InputError(file, line, "direction",
                     "expected up or down, got '" + EscapeForMessage(fields[1]) + "'");
  }
  const std::string kind = fields[2];
  trace->kind =
      kind == SweepKindName(SweepKind::kAmplitude) ? SweepKind::kAmplitude : SweepKind::kFrequency;
  if (kind != SweepKindName(trace->kind)) {
    throw InputError(file, line, "kind",
                     "expected frequency or amplitude, got '" + EscapeForMessage(kind) + "'");
  }
  trace->drive_frequency_rad_s = HzToRadPerSecond(ParsePositive(file, line, "freq_hz", fields[3]));
}

std::string DwellTrace::Describe() const {
  std::string text = sweep + "/" + SweepDirectionName(direction) + " @ " +
                     FormatFrequencyHz(drive_frequency_rad_s) + " Hz";
  const std::string file = source_file.empty() ? kTraceIndexFile : source_file;
  if (source_line > 0) text += StringPrintf(" (%s:%d)", file.c_str(), source_line);
  return text;
}

void WriteTraceSet(const std::vector<DwellTrace>& dwells, const std::string& folder) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) throw InputError(folder, 0, "", "cannot create the folder: " + error.message());
  std::ostringstream index;
  index << "sweep,direction,kind,freq_hz,sample_rate_hz,base_samples,response_samples,"
           "samples_crc32\n";
  std::string samples;
  for (const DwellTrace& dwell : dwells) {
    if (dwell.sweep.empty() || dwell.sweep.find_first_of(",\"\r\n") != std::string::npos) {
      throw InputError("sweep id '" + EscapeForMessage(dwell.sweep) +
                       "' cannot be written as a CSV field");
    }
    index << dwell.sweep << ',' << SweepDirectionName(dwell.direction) << ','
          << SweepKindName(dwell.kind) << ',' << FormatFrequencyHz(dwell.drive_frequency_rad_s)
          << ',' << FormatRoundTrip(dwell.sample_rate_hz) << ',' << dwell.base.size() << ','
          << dwell.response.size() << ',';
    const std::size_t first = samples.size();
    for (float value : dwell.base) PutFloat(value, &samples);
    for (float value : dwell.response) PutFloat(value, &samples);
    index << StringPrintf("%08x", Crc32(samples.data() + first, samples.size() - first)) << '\n';
  }
  WriteFileAtomically(samples, (fs::path(folder) / kTraceSamplesFile).string());
  WriteFileAtomically(index.str(), (fs::path(folder) / kTraceIndexFile).string());
}

std::vector<DwellTrace> ReadTraceSet(const std::string& folder) {
  const std::string index_path = (fs::path(folder) / kTraceIndexFile).string();
  const std::string samples_path = (fs::path(folder) / kTraceSamplesFile).string();
  std::vector<IndexRow> rows = ReadIndex(index_path);
  // The sizes are checked before anything is allocated for the samples.
  std::uint64_t expected = 0;
  for (const IndexRow& row : rows) expected += 4 * (row.base_samples + row.response_samples);
  RequireRegularFile(samples_path);
  std::error_code error;
  const std::uintmax_t size = fs::file_size(samples_path, error);
  if (error || size != expected) {
    throw InputError(samples_path, 0, "",
                     StringPrintf("holds %ju bytes, but %s announces %ju (4 per sample); the two "
                                  "files do not belong together or one was cut short",
                                  static_cast<std::uintmax_t>(size), kTraceIndexFile,
                                  static_cast<std::uintmax_t>(expected)));
  }
  std::ifstream file(samples_path, std::ios::binary);
  std::vector<DwellTrace> dwells;
  std::vector<unsigned char> bytes;
  for (IndexRow& row : rows) {
    bytes.resize(4 * (row.base_samples + row.response_samples));
    if (!file.read(reinterpret_cast<char*>(bytes.data()),
                   static_cast<std::streamsize>(bytes.size()))) {
      throw InputError(samples_path, 0, "", "cannot read the samples file");
    }
    if (row.crc32 && Crc32(bytes.data(), bytes.size()) != *row.crc32) {
      throw InputError(index_path, row.trace.source_line, "samples_crc32",
                       row.trace.Describe() + ": the samples in " + kTraceSamplesFile +
                           " are not the ones this row was written with; the two files come "
                           "from different runs, or one is damaged");
    }
    const unsigned char* sample = bytes.data();
    for (std::vector<float>* channel : {&row.trace.base, &row.trace.response}) {
      channel->resize(channel == &row.trace.base ? row.base_samples : row.response_samples);
      for (float& value : *channel) {
        value = boost::endian::endian_load<float, 4, boost::endian::order::little>(sample);
        sample += 4;
      }
    }
    dwells.push_back(std::move(row.trace));
  }
  return dwells;
}

}  // namespace dwellfit
