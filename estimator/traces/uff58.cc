#include "dwellfit/estimator/traces/uff58.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "glog/logging.h"

namespace dwellfit {
namespace {

constexpr char kWhitespace[] = " \t\r\n";

std::string_view Trim(std::string_view text) {
  const std::size_t first = text.find_first_not_of(kWhitespace);
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(kWhitespace) - first + 1);
}

// "NONE" and blank labels read as "".
std::string Label(std::string_view text) {
  const std::string_view trimmed = Trim(text);
  return trimmed == "NONE" ? std::string() : std::string(trimmed);
}

// The length of the character at `i` of `text`: a well-formed UTF-8
// sequence, or any other single byte.
std::size_t CharacterLength(std::string_view text, std::size_t i) {
  const unsigned char c = static_cast<unsigned char>(text[i]);
  const std::size_t length = c >= 0xF5 ? 1 : c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 1;
  for (std::size_t k = 1; k < length; ++k) {
    if (i + k >= text.size() || (static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80) return 1;
  }
  return length;
}

// The characters [first, first + width) of `line` (UTF-8 labels such as
// "m/s²" count one column per character).
std::string_view Column(std::string_view line, std::size_t first, std::size_t width) {
  std::size_t begin = line.size(), character = 0, i = 0;
  for (; i < line.size() && character < first + width; ++character) {
    if (character == first) begin = i;
    i += CharacterLength(line, i);
  }
  if (begin >= line.size()) return {};
  return line.substr(begin, i - begin);
}

// Walks the file's bytes line by line and names positions in messages.
class Cursor {
 public:
  Cursor(std::string_view bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  bool AtEnd() const { return offset_ >= bytes_.size(); }
  std::size_t offset() const { return offset_; }
  std::size_t left() const { return bytes_.size() - offset_; }
  int line() const { return line_; }
  const std::string& name() const { return name_; }

  // The next line without its end ("\n" or "\r\n"); false at the end.
  bool NextLine(std::string_view* line) {
    if (AtEnd()) return false;
    const std::size_t end = std::min(bytes_.find('\n', offset_), bytes_.size());
    *line = bytes_.substr(offset_, end - offset_);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    offset_ = std::min(end + 1, bytes_.size());
    ++line_;
    return true;
  }

  // The next line of a record; throws InputError at the end of the file.
  std::string_view Record(const char* field) {
    std::string_view line;
    if (!NextLine(&line)) {
      Fail(field, "the file ends inside a data set 58; give the whole file as exported");
    }
    return line;
  }

  // The next `size` bytes (checked against what is left by the caller).
  std::string_view Take(std::size_t size) {
    const std::string_view taken = bytes_.substr(offset_, size);
    offset_ += taken.size();
    return taken;
  }

  // Skips line ends (the binary values are followed by "    -1").
  void SkipLineEnds() {
    while (!AtEnd() && (bytes_[offset_] == '\r' || bytes_[offset_] == '\n')) {
      if (bytes_[offset_] == '\n') ++line_;
      ++offset_;
    }
  }

  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    throw InputError(name_, line_, field, what);
  }
  [[noreturn]] void FailAtByte(std::size_t byte, const std::string& field,
                               const std::string& what) const {
    throw InputError(name_, 0, field, StringPrintf("at byte offset %zu: ", byte) + what);
  }

 private:
  std::string_view bytes_;
  std::string name_;
  std::size_t offset_ = 0;
  int line_ = 0;
};

// A whole number in the characters [first, first + width) of `line`.
std::int64_t ParseInteger(const Cursor& cursor, std::string_view line, std::size_t first,
                          std::size_t width, const char* field) {
  const std::string text(Trim(Column(line, first, width)));
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || text.find_first_not_of("+-0123456789") != std::string::npos || *end != '\0' ||
      std::llabs(value) > (1LL << 40)) {
    cursor.Fail(field, StringPrintf("expected a whole number in columns %zu-%zu, got '", first + 1,
                                    first + width) +
                           EscapeForMessage(text) + "'; check that the file is UFF data set 58");
  }
  return value;
}

int ParseInt(const Cursor& cursor, std::string_view line, std::size_t first, std::size_t width,
             const char* field) {
  const std::int64_t value = ParseInteger(cursor, line, first, width, field);
  if (std::llabs(value) > std::numeric_limits<int>::max()) {
    cursor.Fail(field, "the number is out of range; check that the file is UFF data set 58");
  }
  return static_cast<int>(value);
}

// `text`, the field of columns [first, first + width) of the cursor's line,
// as a finite real number (Fortran E or D notation); fails naming `field`.
double ToReal(const Cursor& cursor, std::string_view text, std::size_t first, std::size_t width,
              const std::string& field) {
  std::string copy(Trim(text));
  for (char& c : copy) {
    if (c == 'd' || c == 'D') c = 'E';
  }
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (copy.empty() || copy.find_first_not_of("+-.0123456789eE") != std::string::npos ||
      *end != '\0' || !std::isfinite(value)) {
    cursor.Fail(field, StringPrintf("expected a finite number in columns %zu-%zu, got '", first + 1,
                                    first + width) +
                           EscapeForMessage(Trim(text)) + "'");
  }
  return value;
}

double ParseReal(const Cursor& cursor, std::string_view line, std::size_t first, std::size_t width,
                 const char* field) {
  return ToReal(cursor, Column(line, first, width), first, width, field);
}

// Record 6: Format(2(I5,I10),2(1X,10A1,I10,I4)).
void ParseRecord6(const Cursor& c, std::string_view line, Uff58Record* r) {
  r->function_type = ParseInt(c, line, 0, 5, "function type (record 6)");
  r->function_id = ParseInt(c, line, 5, 10, "function id (record 6)");
  r->version = ParseInt(c, line, 15, 5, "version number (record 6)");
  r->load_case = ParseInt(c, line, 20, 10, "load case (record 6)");
  r->response_entity = Label(Column(line, 31, 10));
  r->response_node = ParseInt(c, line, 41, 10, "response node (record 6)");
  r->response_direction = ParseInt(c, line, 51, 4, "response direction (record 6)");
  r->reference_entity = Label(Column(line, 56, 10));
  r->reference_node = ParseInt(c, line, 66, 10, "reference node (record 6)");
  r->reference_direction = ParseInt(c, line, 76, 4, "reference direction (record 6)");
}

// Record 7: Format(3I10,3E13.5).
void ParseRecord7(const Cursor& c, std::string_view line, Uff58Record* r) {
  r->ordinate_data_type = ParseInt(c, line, 0, 10, "ordinate data type (record 7)");
  r->value_count = ParseInteger(c, line, 10, 10, "number of values (record 7)");
  if (r->value_count < 0) c.Fail("number of values (record 7)", "is negative");
  r->abscissa_spacing = ParseInt(c, line, 20, 10, "abscissa spacing (record 7)");
  r->abscissa_min = ParseReal(c, line, 30, 13, "abscissa minimum (record 7)");
  r->abscissa_increment = ParseReal(c, line, 43, 13, "abscissa increment (record 7)");
  r->z_axis_value = ParseReal(c, line, 56, 13, "z-axis value (record 7)");
}

// Records 8-11: Format(I10,3I5,2(1X,20A1)).
Uff58Axis ParseAxis(const Cursor& c, std::string_view line, const char* record) {
  const std::string at = std::string(" (") + record + ")";
  Uff58Axis axis;
  axis.specific_data_type = ParseInt(c, line, 0, 10, ("specific data type" + at).c_str());
  axis.length_exponent = ParseInt(c, line, 10, 5, ("length units exponent" + at).c_str());
  axis.force_exponent = ParseInt(c, line, 15, 5, ("force units exponent" + at).c_str());
  axis.temperature_exponent = ParseInt(c, line, 20, 5, ("temperature units exponent" + at).c_str());
  axis.label = Label(Column(line, 26, 20));
  axis.units = Label(Column(line, 47, 20));
  return axis;
}

// The 58b header line's fields, Format(I6,A1,I6,I6,I12,I12,...).
struct BinaryLayout {
  bool little_endian = true;
  std::int64_t bytes = 0;
};

BinaryLayout ParseBinaryHeader(const Cursor& c, std::string_view line) {
  const int order = ParseInt(c, line, 7, 6, "byte ordering (58b header)");
  const int format = ParseInt(c, line, 13, 6, "floating-point format (58b header)");
  const int ascii_lines = ParseInt(c, line, 19, 12, "number of ASCII lines (58b header)");
  BinaryLayout layout;
  layout.bytes = ParseInteger(c, line, 31, 12, "number of bytes (58b header)");
  if (order != 1 && order != 2) {
    c.Fail("byte ordering (58b header)",
           "expected 1 (little-endian) or 2 (big-endian), got " + std::to_string(order));
  }
  if (format != 2) {
    c.Fail("floating-point format (58b header)", "expected 2 (IEEE 754), got " +
                                                     std::to_string(format) +
                                                     "; export the file with IEEE floating point");
  }
  if (ascii_lines != 11) {
    c.Fail("number of ASCII lines (58b header)",
           "expected 11 (records 1-11), got " + std::to_string(ascii_lines));
  }
  if (layout.bytes < 0) c.Fail("number of bytes (58b header)", "is negative");
  layout.little_endian = order == 1;
  return layout;
}

// Why the values of `r` are not read ("" when they are).
std::string UnreadForm(const Uff58Record& r) {
  if (r.ordinate_data_type == 5 || r.ordinate_data_type == 6) return "complex ordinate";
  if (r.ordinate_data_type != 2 && r.ordinate_data_type != 4) {
    return "ordinate data type " + std::to_string(r.ordinate_data_type);
  }
  if (r.abscissa_spacing != 1) return "uneven abscissa spacing";
  return "";
}

// Record 12, binary: `layout.bytes` bytes of IEEE 754 values.
void ReadBinaryValues(Cursor& c, const BinaryLayout& layout, Uff58Record* r) {
  const std::size_t start = c.offset();
  if (static_cast<std::uint64_t>(layout.bytes) > c.left()) {
    c.FailAtByte(start, "number of bytes (58b header)",
                 StringPrintf("announces %lld bytes of values, the file holds %zu more; give the "
                              "whole file as exported",
                              static_cast<long long>(layout.bytes), c.left()));
  }
  const std::string_view data = c.Take(static_cast<std::size_t>(layout.bytes));
  if (!r->not_read.empty()) return;
  const std::size_t size = r->ordinate_data_type == 2 ? 4 : 8;
  if (static_cast<std::uint64_t>(r->value_count) * size != data.size()) {
    c.FailAtByte(start, "number of bytes (58b header)",
                 StringPrintf("%zu bytes do not hold the %lld values of %zu bytes that record 7 "
                              "announces; check the export",
                              data.size(), static_cast<long long>(r->value_count), size));
  }
  r->values.resize(static_cast<std::size_t>(r->value_count));
  for (std::size_t i = 0; i < r->values.size(); ++i) {
    std::uint64_t bits = 0;
    for (std::size_t k = 0; k < size; ++k) {
      const std::size_t byte = layout.little_endian ? size - 1 - k : k;
      bits = (bits << 8) | static_cast<unsigned char>(data[i * size + byte]);
    }
    if (size == 4) {
      const auto narrow = static_cast<std::uint32_t>(bits);
      float value;
      std::memcpy(&value, &narrow, 4);
      r->values[i] = value;
    } else {
      std::memcpy(&r->values[i], &bits, 8);
    }
    if (!std::isfinite(r->values[i])) {
      c.FailAtByte(start + i * size, "value " + std::to_string(i + 1),
                   "is not a finite number; check the export");
    }
  }
}

// Record 12, ASCII: fixed-width fields, E13.5 (single) or E20.12 (double).
void ReadAsciiValues(Cursor& c, Uff58Record* r) {
  const std::size_t width = r->ordinate_data_type == 2 ? 13 : 20;
  if (static_cast<std::uint64_t>(r->value_count) > c.left() / width) {
    // Named at record 7, the set number's line + 7.
    throw InputError(
        c.name(), r->line + 7, "number of values (record 7)",
        StringPrintf("announces %lld values, more than the %zu bytes left hold; give the "
                     "whole file as exported",
                     static_cast<long long>(r->value_count), c.left()));
  }
  r->values.reserve(static_cast<std::size_t>(r->value_count));
  while (r->values.size() < static_cast<std::size_t>(r->value_count)) {
    std::string_view line = c.Record("values (record 12)");
    line = line.substr(0, line.find_last_not_of(kWhitespace) + 1);
    if (line.empty() || Trim(line) == "-1") {
      c.Fail("values (record 12)",
             StringPrintf("%zu values where record 7 announces %lld; check the export",
                          r->values.size(), static_cast<long long>(r->value_count)));
    }
    for (std::size_t first = 0; first < line.size(); first += width) {
      const std::string at = "value " + std::to_string(r->values.size() + 1);
      if (r->values.size() == static_cast<std::size_t>(r->value_count)) {
        c.Fail(at, StringPrintf("more values than the %lld record 7 announces; check the export",
                                static_cast<long long>(r->value_count)));
      }
      r->values.push_back(ToReal(c, line.substr(first, width), first, width, at));
    }
  }
}

// Skips the lines up to and including the closing "    -1"; `start` is the
// line of the set number, for the message.
void SkipToEndOfSet(Cursor& c, int start) {
  std::string_view line;
  while (c.NextLine(&line)) {
    if (Trim(line) == "-1") return;
  }
  c.Fail("", StringPrintf("the data set at line %d has no closing '    -1' line; give the "
                          "whole file as exported",
                          start));
}

void ExpectEndOfSet(Cursor& c, const Uff58Record& r) {
  if (r.binary) c.SkipLineEnds();
  const std::string_view line = c.Record("end of data set");
  if (Trim(line) != "-1") {
    c.Fail("end of data set", StringPrintf("expected '    -1' closing the data set 58 at line "
                                           "%d, got '%s'; check its number of values",
                                           r.line, EscapeForMessage(line).c_str()));
  }
}

// Records 1-12 and the closing line of a data set 58 whose number line
// `header` was just read.
Uff58Record ReadSet58(Cursor& c, std::string_view header, bool binary) {
  Uff58Record r;
  r.binary = binary;
  r.line = c.line();
  BinaryLayout layout;
  if (binary) layout = ParseBinaryHeader(c, header);
  for (int i = 0; i < 5; ++i) {
    const std::string_view line = c.Record("ID line");
    r.id_lines[i] = std::string(line.substr(0, line.find_last_not_of(kWhitespace) + 1));
  }
  ParseRecord6(c, c.Record("record 6"), &r);
  ParseRecord7(c, c.Record("record 7"), &r);
  r.abscissa = ParseAxis(c, c.Record("record 8"), "record 8");
  r.ordinate = ParseAxis(c, c.Record("record 9"), "record 9");
  r.denominator = ParseAxis(c, c.Record("record 10"), "record 10");
  r.z_axis = ParseAxis(c, c.Record("record 11"), "record 11");
  r.not_read = UnreadForm(r);
  if (binary) {
    ReadBinaryValues(c, layout, &r);
  } else if (!r.not_read.empty()) {
    SkipToEndOfSet(c, r.line);
    return r;
  } else {
    ReadAsciiValues(c, &r);
  }
  ExpectEndOfSet(c, r);
  return r;
}

}  // namespace

std::vector<Uff58Record> ParseUff58(std::string_view bytes, const std::string& name) {
  Cursor c(bytes, name);
  std::vector<Uff58Record> records;
  std::string_view line;
  while (c.NextLine(&line)) {
    if (Trim(line).empty()) continue;  // blank lines between data sets
    if (Trim(line) != "-1") {
      c.Fail("", "expected '    -1' opening a data set, got '" + EscapeForMessage(line) +
                     "'; give a universal file (UFF)");
    }
    const std::size_t offset = c.offset();
    const std::string_view header = c.Record("data set number");
    const int number = ParseInt(c, header, 0, 6, "data set number");
    const bool binary = Column(header, 6, 1) == "b" || Column(header, 6, 1) == "B";
    if (number != 58) {
      SkipToEndOfSet(c, c.line());
      continue;
    }
    records.push_back(ReadSet58(c, header, binary));
    records.back().offset = static_cast<std::int64_t>(offset);
  }
  return records;
}

std::vector<Uff58Record> ReadUff58File(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(path, 0, "",
                     std::filesystem::exists(path, error)
                         ? "is not a regular file (a folder, device or pipe); give the file"
                         : "cannot open the file; check the path");
  }
  std::ifstream file(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << file.rdbuf();
  if (!file) throw InputError(path, 0, "", "cannot read the file; check its permissions");
  return ParseUff58(bytes.str(), path);
}

namespace {

// `text` ("NONE" when empty) cut or padded with blanks to `width` characters.
std::string Fit(const std::string& text, std::size_t width) {
  std::string fitted(Column(text.empty() ? "NONE" : text, 0, width));
  std::size_t characters = 0;
  for (std::size_t i = 0; i < fitted.size(); i += CharacterLength(fitted, i)) ++characters;
  return fitted + std::string(width - characters, ' ');
}

void AppendAxis(const Uff58Axis& axis, std::string* out) {
  *out += StringPrintf("%10d%5d%5d%5d ", axis.specific_data_type, axis.length_exponent,
                       axis.force_exponent, axis.temperature_exponent) +
          Fit(axis.label, 20) + " " + Fit(axis.units, 20) + "\n";
}

// Record 12 in the layout the header announces.
void AppendValues(const Uff58Record& r, bool binary, std::string* out) {
  const bool single = r.ordinate_data_type == 2;
  for (std::size_t i = 0; i < r.values.size(); ++i) {
    if (binary) {
      std::uint64_t bits = 0;
      if (single) {
        const float value = static_cast<float>(r.values[i]);
        std::uint32_t narrow;
        std::memcpy(&narrow, &value, 4);
        bits = narrow;
      } else {
        std::memcpy(&bits, &r.values[i], 8);
      }
      for (int k = 0; k < (single ? 4 : 8); ++k) out->push_back(static_cast<char>(bits >> (8 * k)));
      continue;
    }
    *out += StringPrintf(single ? "%13.5E" : "%20.12E", r.values[i]);
    const std::size_t per_line = single ? 6 : 4;
    if ((i + 1) % per_line == 0 || i + 1 == r.values.size()) *out += "\n";
  }
}

}  // namespace

void AppendUff58(const Uff58Record& r, bool binary, std::string* out) {
  CHECK(r.ordinate_data_type == 2 || r.ordinate_data_type == 4) << "real values only";
  CHECK_EQ(r.abscissa_spacing, 1) << "even spacing only";
  CHECK_EQ(static_cast<std::size_t>(r.value_count), r.values.size());
  const std::size_t bytes = r.values.size() * (r.ordinate_data_type == 2 ? 4 : 8);
  *out += "    -1\n";
  *out += binary ? StringPrintf("%6d%c%6d%6d%12d%12zu%6d%6d%12d%12d\n", 58, 'b', 1, 2, 11, bytes, 0,
                                0, 0, 0)
                 : std::string("    58\n");
  for (const std::string& id : r.id_lines) *out += (id.empty() ? "NONE" : id) + "\n";
  *out += StringPrintf("%5d%10d%5d%10d ", r.function_type, r.function_id, r.version, r.load_case) +
          Fit(r.response_entity, 10) +
          StringPrintf("%10d%4d ", r.response_node, r.response_direction) +
          Fit(r.reference_entity, 10) +
          StringPrintf("%10d%4d\n", r.reference_node, r.reference_direction);
  *out += StringPrintf("%10d%10zu%10d%13.5E%13.5E%13.5E\n", r.ordinate_data_type, r.values.size(),
                       1, r.abscissa_min, r.abscissa_increment, r.z_axis_value);
  for (const Uff58Axis* axis : {&r.abscissa, &r.ordinate, &r.denominator, &r.z_axis}) {
    AppendAxis(*axis, out);
  }
  AppendValues(r, binary, out);
  *out += "    -1\n";
}

}  // namespace dwellfit
