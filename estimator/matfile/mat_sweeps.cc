#include "dwellfit/estimator/matfile/mat_sweeps.h"

#include <matio.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv_writer.h"
#include "dwellfit/estimator/matfile/child_process.h"
#include "dwellfit/estimator/matfile/mat_handles.h"
#include "dwellfit/estimator/matfile/mat_v5_check.h"

namespace dwellfit {
namespace {

// The CSV's columns, in SweepRowFields' order; the first two are text.
constexpr std::array<const char*, 9> kColumns = {"sweep",     "direction", "freq_hz",
                                                 "a_base",    "a",         "phase_deg",
                                                 "phase_rad", "sigma",     "a_base_sigma"};
constexpr int kNumRequired = 5;
constexpr int kNumText = 2;
// The longest a v7.3 file's reading process may take (a file of 24,576 rows
// with cell arrays of ids: about 0.5 s).
constexpr std::chrono::seconds kV73ReadLimit{60};

constexpr char kLayout[] =
    "a sweeps MAT file holds the cell arrays sweep and direction and the double vectors "
    "freq_hz, a_base, a (required), phase_deg or phase_rad, sigma, a_base_sigma (optional), one "
    "value per row (docs/matlab.md)";

// Each column's values as text, one per row; empty for a column not given.
using Table = std::array<std::vector<std::string>, kColumns.size()>;

[[noreturn]] void Fail(const std::string& path, const std::string& variable, std::size_t row,
                       const std::string& what) {
  std::string where = variable.empty() ? "" : "variable '" + EscapeForMessage(variable) + "'";
  if (row > 0) where += (where.empty() ? "row " : ", row ") + std::to_string(row);
  throw InputError(path, 0, "", (where.empty() ? "" : where + ": ") + what);
}

// The number of values of a vector (either orientation; 0 x 0 is empty).
std::size_t Length(const std::string& path, const std::string& name, std::size_t row,
                   const matvar_t& var) {
  const bool matrix = var.rank == 2 && var.dims != nullptr;
  if (matrix && (var.dims[0] == 0 || var.dims[1] == 0)) return 0;
  if (!matrix || (var.dims[0] != 1 && var.dims[1] != 1)) {
    std::string shape;
    for (int i = 0; var.dims != nullptr && i < var.rank; ++i) {
      shape += (i ? " x " : "") + std::to_string(var.dims[i]);
    }
    Fail(path, name, row, "is a " + shape + " array; give a vector (x(:) in MATLAB)");
  }
  return var.dims[0] * var.dims[1];
}

// Throws unless `var` is a char array whose data hold all its chars.
void CheckChars(const std::string& path, const std::string& name, std::size_t row,
                const matvar_t* var) {
  if (var == nullptr || var->class_type != MAT_C_CHAR || var->rank != 2 || var->dims == nullptr) {
    Fail(path, name, row, "is not a char string; give each row's text as a char string");
  }
  const std::size_t n = var->dims[0] * var->dims[1];
  if ((var->data_size != 1 && var->data_size != 2) || var->nbytes < n * var->data_size ||
      (n > 0 && var->data == nullptr)) {
    Fail(path, name, row, "the chars cannot be read; save the text as a char string");
  }
}

// Chars [begin, end) in steps of `step` of a char array, as UTF-8 (its
// bytes, or UTF-16 code units of the BMP).
std::string Chars(const matvar_t& var, std::size_t begin, std::size_t end, std::size_t step) {
  std::string text;
  for (std::size_t i = begin; i < end; i += step) {
    const bool wide = var.data_size == 2;
    const unsigned unit = wide ? static_cast<const std::uint16_t*>(var.data)[i]
                               : static_cast<const unsigned char*>(var.data)[i];
    if (unit < 0x80 || !wide) {
      text += static_cast<char>(unit);
    } else if (unit < 0x800) {
      text += {static_cast<char>(0xC0 | unit >> 6), static_cast<char>(0x80 | (unit & 0x3F))};
    } else {
      text += {static_cast<char>(0xE0 | unit >> 12), static_cast<char>(0x80 | (unit >> 6 & 0x3F)),
               static_cast<char>(0x80 | (unit & 0x3F))};
    }
  }
  return text;
}

// A text column: a cell array of char strings, or a char matrix of one row
// per row (column-major; padding spaces and NULs at the end cut off).
std::vector<std::string> ReadText(const std::string& path, const std::string& name, matvar_t* var) {
  if (var->class_type == MAT_C_CHAR) {
    CheckChars(path, name, 0, var);
    const std::size_t rows = var->dims[0], end = rows * var->dims[1];
    std::vector<std::string> values(rows);
    for (std::size_t i = 0; i < rows; ++i) {
      values[i] = Chars(*var, i, end, rows);
      values[i].erase(values[i].find_last_not_of(std::string(" \0", 2)) + 1);
    }
    return values;
  }
  if (var->class_type != MAT_C_CELL) {
    Fail(path, name, 0,
         "is neither a cell array nor a char matrix; give a cell array of char strings, one per "
         "row (cellstr(x) in MATLAB; a NumPy array of dtype=object for scipy.io.savemat)");
  }
  std::vector<std::string> values(Length(path, name, 0, *var));
  for (std::size_t i = 0; i < values.size(); ++i) {
    const matvar_t* cell = Mat_VarGetCell(var, static_cast<int>(i));
    CheckChars(path, name, i + 1, cell);
    if (cell->dims[0] > 1) Fail(path, name, i + 1, "give the text as one row of chars");
    values[i] = Chars(*cell, 0, cell->dims[0] * cell->dims[1], 1);
  }
  return values;
}

// A numeric column: a real double vector, as round-trip text.
std::vector<std::string> ReadNumbers(const std::string& path, const std::string& name,
                                     const matvar_t& var) {
  if (var.class_type != MAT_C_DOUBLE || var.isComplex || var.isLogical) {
    Fail(path, name, 0,
         "is not a real double array; give the numbers as doubles (double(x) in MATLAB; a "
         "float64 NumPy array)");
  }
  std::vector<std::string> values(Length(path, name, 0, var));
  if (var.data_size != sizeof(double) || var.nbytes < values.size() * sizeof(double) ||
      (!values.empty() && var.data == nullptr)) {
    Fail(path, name, 0, "the values cannot be read; save the vector again");
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    values[i] = FormatRoundTrip(static_cast<const double*>(var.data)[i]);
  }
  return values;
}

// Reads every variable into `table`; throws on an unknown or missing one.
void ReadTable(const std::string& path, mat_t* mat, Table* table, std::vector<bool>* given) {
  // zlib inflates at most 1032-fold: a variable claiming more values is damaged
  // (and would make libmatio allocate for them).
  std::error_code error;
  const double max_values = 1032.0 * static_cast<double>(std::filesystem::file_size(path, error));
  std::vector<std::string> names;
  while (MatVar info{Mat_VarReadNextInfo(mat)}) {
    if (info->name == nullptr) continue;
    double values = 1.0;
    for (int i = 0; info->dims != nullptr && i < info->rank; ++i) {
      values *= std::max<double>(static_cast<double>(info->dims[i]), 1.0);  // N x 0 too
    }
    if (values > max_values) {
      Fail(path, info->name, 0, "claims more values than the file holds; the file is damaged");
    }
    names.emplace_back(info->name);
  }
  for (const std::string& name : names) {
    const auto column = std::find(kColumns.begin(), kColumns.end(), name);
    if (column == kColumns.end()) Fail(path, name, 0, std::string("unknown variable; ") + kLayout);
    const auto index = static_cast<std::size_t>(column - kColumns.begin());
    MatVar var{Mat_VarRead(mat, name.c_str())};
    if (!var) Fail(path, name, 0, "cannot be read; save the file again");
    (*table)[index] =
        index < kNumText ? ReadText(path, name, var.get()) : ReadNumbers(path, name, *var);
    (*given)[index] = true;
  }
  for (int i = 0; i < kNumRequired; ++i) {
    if (!(*given)[i]) Fail(path, kColumns[i], 0, std::string("is missing; ") + kLayout);
  }
  if ((*given)[5] && (*given)[6]) {
    Fail(path, "phase_rad", 0, "the file has both phase_deg and phase_rad; keep one of them");
  }
  for (std::size_t i = 0; i < kColumns.size(); ++i) {
    if ((*given)[i] && (*table)[i].size() != (*table)[0].size()) {
      Fail(path, kColumns[i], 0,
           "has " + std::to_string((*table)[i].size()) + " values but sweep has " +
               std::to_string((*table)[0].size()) + "; give every variable one value per row");
    }
  }
  if ((*table)[0].empty()) Fail(path, "sweep", 0, "is empty; give one row per dwell");
}

// Opens the MAT file `path` (when `has_header`, else reports it is none) and
// reads its variables into `table`.
void OpenAndReadTable(const std::string& path, bool has_header, Table* table,
                      std::vector<bool>* given) {
  MatFile mat{has_header ? Mat_Open(path.c_str(), MAT_ACC_RDONLY) : nullptr};
  if (!mat) {
    Fail(path, "", 0,
         "is not a MAT file that libmatio reads (v5, v7 or v7.3); save it with MATLAB's save or "
         "scipy.io.savemat");
  }
  ReadTable(path, mat.get(), table, given);
}

// The table handed from the reading child to the caller: per column a flag
// byte (given or not), then the count of values and each value, every count
// and length 8 bytes in the machine's order. An error is 'E' and its text.
void PutSize(std::size_t size, std::string* out) {
  out->append(reinterpret_cast<const char*>(&size), sizeof(size));
}
bool GetSize(const std::string& in, std::size_t* at, std::size_t* size) {
  if (in.size() - *at < sizeof(*size)) return false;
  std::memcpy(size, in.data() + *at, sizeof(*size));
  *at += sizeof(*size);
  return true;
}
std::string EncodeTable(const Table& table, const std::vector<bool>& given) {
  std::string out = "T";
  for (std::size_t i = 0; i < table.size(); ++i) {
    out += given[i] ? '1' : '0';
    PutSize(table[i].size(), &out);
    for (const std::string& value : table[i]) {
      PutSize(value.size(), &out);
      out += value;
    }
  }
  return out;
}
bool DecodeTable(const std::string& in, Table* table, std::vector<bool>* given) {
  std::size_t at = 1;
  for (std::size_t i = 0; i < table->size(); ++i) {
    std::size_t count = 0;
    if (at >= in.size()) return false;
    (*given)[i] = in[at++] == '1';
    if (!GetSize(in, &at, &count) || count > in.size()) return false;
    (*table)[i].resize(count);
    for (std::string& value : (*table)[i]) {
      std::size_t length = 0;
      if (!GetSize(in, &at, &length) || in.size() - at < length) return false;
      value = in.substr(at, length);
      at += length;
    }
  }
  return at == in.size();
}

// A v7.3 file is HDF5, which Debian's HDF5 1.10.8 does not parse safely when
// the file is damaged (out-of-bounds reads, a use-after-free): it is read in a
// child process (child_process.h), and what becomes of that process becomes a
// message about the file.
void ReadTableInChild(const std::string& path, Table* table, std::vector<bool>* given) {
  const std::string prefix = path + ": ";
  const ChildOutcome outcome = RunInChildProcess(
      [&]() -> std::string {
        Table child_table;
        std::vector<bool> child_given(kColumns.size(), false);
        try {
          OpenAndReadTable(path, true, &child_table, &child_given);
        } catch (const InputError& error) {
          return "E" + std::string(error.what());
        }
        return EncodeTable(child_table, child_given);
      },
      kV73ReadLimit);
  const char kind = outcome.completed && !outcome.bytes.empty() ? outcome.bytes[0] : '\0';
  if (kind == 'E') {
    const std::string& what = outcome.bytes;
    const bool prefixed = what.compare(1, prefix.size(), prefix) == 0;
    throw InputError(path, 0, "", what.substr(prefixed ? 1 + prefix.size() : 1));
  }
  if (kind != 'T' || !DecodeTable(outcome.bytes, table, given)) {
    Fail(path, "", 0,
         "HDF5 could not read this v7.3 file (the reading process " +
             (outcome.completed ? std::string("handed back no table") : outcome.failure) +
             "); the file is damaged: save it again, or as v7 (save -v7) or CSV");
  }
}

// An error of the row checks, reworded for a MAT file: "variable 'a', row 5".
[[noreturn]] void Reword(const std::string& path, const InputError& error) {
  std::string what = error.what();
  std::string prefix = path + (error.line() > 0 ? ":" + std::to_string(error.line()) : "") + ": ";
  if (!error.field().empty()) prefix += "field '" + error.field() + "': ";
  if (what.compare(0, prefix.size(), prefix) == 0) what.erase(0, prefix.size());
  for (std::size_t at = what.find("line "); at != std::string::npos; at = what.find("line ", at)) {
    what.replace(at, 5, "row ");
  }
  Fail(path, error.field(), static_cast<std::size_t>(std::max(error.line(), 0)), what);
}

}  // namespace

bool IsMatFileName(const std::string& path) {
  if (path.size() < 4) return false;
  std::string extension = path.substr(path.size() - 4);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".mat";
}

LoadedSweeps LoadSweepsMat(const std::string& path) {
  const std::string not_a_file = NotARegularFile(path);
  if (!not_a_file.empty()) Fail(path, "", 0, not_a_file + "; give the path of a sweeps MAT file");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) Fail(path, "", 0, "cannot open the file; check the path and permissions");
  const std::string bytes(std::istreambuf_iterator<char>(stream), {});
  const std::string damage = CheckMatV5(bytes);
  if (!damage.empty()) Fail(path, "", 0, "the file is damaged (" + damage + "); save it again");
  Table table;
  std::vector<bool> given(kColumns.size(), false);
  if (IsMatV73(bytes)) {
    ReadTableInChild(path, &table, &given);
  } else {
    OpenAndReadTable(path, HasMatHeader(bytes), &table, &given);
  }
  std::size_t next = 0;
  std::array<char * SweepRowFields::*, kColumns.size()> members = {
      &SweepRowFields::sweep,     &SweepRowFields::direction, &SweepRowFields::freq_hz,
      &SweepRowFields::a_base,    &SweepRowFields::a,         &SweepRowFields::phase_deg,
      &SweepRowFields::phase_rad, &SweepRowFields::sigma,     &SweepRowFields::a_base_sigma};
  try {
    return LoadSweepsFromRows(path, 0, [&](SweepRowFields* row, int* line) {
      if (next == table[0].size()) return false;
      for (std::size_t i = 0; i < kColumns.size(); ++i) {
        row->*members[i] = given[i] ? table[i][next].data() : nullptr;
      }
      *line = static_cast<int>(++next);
      return true;
    });
  } catch (const InputError& error) {
    Reword(path, error);
  }
}

}  // namespace dwellfit
