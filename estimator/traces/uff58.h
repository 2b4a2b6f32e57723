// Universal File Format (UFF) data set 58, "Function at Nodal DOF": the time
// histories (and spectra) that test systems such as Simcenter Testlab/LMS,
// HBM catman or B&K export. A UFF file is a sequence of data sets, each
// between two lines "    -1"; the line after the opening one holds the set's
// number in columns 1-6 (58), and a `b` in column 7 marks the binary variant
// 58b. Records 1-11 are text lines in fixed columns:
//
//   1-5  ID lines 1-5 (80A1): description, run, date, load case, ...
//   6    Format(2(I5,I10),2(1X,10A1,I10,I4)): function type (1 time
//        response), function id, version, load case, response entity, node
//        and direction, reference entity, node and direction
//   7    Format(3I10,3E13.5): ordinate data type (2 real single, 4 real
//        double, 5/6 complex), number of values, abscissa spacing (1 even),
//        abscissa minimum, abscissa increment [abscissa unit], z-axis value
//   8-11 Format(I10,3I5,2(1X,20A1)): abscissa, ordinate (numerator), ordinate
//        denominator and z-axis characteristics: specific data type (17
//        time, 12 acceleration, ...), length, force and temperature unit
//        exponents, axis label and axis units label
//   12   the values: ASCII, 6 per line in E13.5 (single) or 4 per line in
//        E20.12 (double); binary (58b), the raw IEEE-754 values.
//
// A 58b header line adds, in Format(I6,A1,I6,I6,I12,I12,...): the byte
// ordering (1 little-endian, 2 big-endian), the floating-point format (2
// IEEE 754), the number of ASCII lines that follow (11, records 1-11) and the
// number of bytes of values after them, which start right after record 11's
// line end and are followed by the closing "    -1".
//
// Read: real single and double precision with even abscissa spacing, ASCII
// and binary. A data set 58 of another form (complex, uneven abscissa) is
// listed with its header and the reason it was not read (no values); other
// data sets (151, 164, 2411, ...) are skipped. Column positions count UTF-8
// characters (labels such as "m/s²"). Source: the I-DEAS universal file
// format description of data set 58 (SDRC), as quoted by pyuff.
#ifndef DWELLFIT_ESTIMATOR_TRACES_UFF58_H_
#define DWELLFIT_ESTIMATOR_TRACES_UFF58_H_

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dwellfit {

// Records 8-11: the characteristics of one axis.
struct Uff58Axis {
  int specific_data_type = 0;  // 0 unknown, 1 general, 12 acceleration, 17 time, ...
  int length_exponent = 0;     // units exponents (data type 1 or scalar directions)
  int force_exponent = 0;
  int temperature_exponent = 0;
  std::string label;  // axis label ("" for NONE or blank)
  std::string units;  // axis units label, e.g. "s", "g", "V" ("" for NONE)
};

// One data set 58 or 58b.
struct Uff58Record {
  std::array<std::string, 5> id_lines;  // records 1-5, trailing blanks removed
  // Record 6.
  int function_type = 0;  // 0 general, 1 time response, 4 FRF, ...
  int function_id = 0;
  int version = 0;
  int load_case = 0;
  std::string response_entity;
  int response_node = 0;
  int response_direction = 0;  // 0 scalar, +-1..+-6
  std::string reference_entity;
  int reference_node = 0;
  int reference_direction = 0;
  // Record 7.
  int ordinate_data_type = 2;       // 2 real single, 4 real double
  std::int64_t value_count = 0;     // number of values (even spacing)
  int abscissa_spacing = 1;         // 1 even, 0 uneven
  double abscissa_min = 0.0;        // [abscissa unit, s for time]
  double abscissa_increment = 0.0;  // [abscissa unit]
  double z_axis_value = 0.0;
  // Records 8-11.
  Uff58Axis abscissa, ordinate, denominator, z_axis;
  // Record 12: the ordinate values (empty when `not_read` says why).
  std::vector<double> values;
  std::string not_read;     // "" or why the values were not read (complex, ...)
  bool binary = false;      // 58b
  int line = 0;             // line of the set number ("    58") in the file
  std::int64_t offset = 0;  // its byte offset
};

// Every data set 58 of `bytes`, the contents of the file `name` (for the
// messages), in file order. Throws InputError naming the file, the line (in
// records 1-11 and ASCII values) or byte offset (binary values) and the
// field, and saying what to do, for what it cannot read. Counts are checked
// against the bytes left before anything is allocated.
std::vector<Uff58Record> ParseUff58(std::string_view bytes, const std::string& name);

// Reads the file at `path` (a regular file) with ParseUff58.
std::vector<Uff58Record> ReadUff58File(const std::string& path);

// Appends `record` as a data set 58 (ASCII: E13.5 for ordinate type 2, E20.12
// for 4) or 58b (little-endian IEEE 754) to `out`, with "    -1" lines and
// "\n" line ends. Real values with even spacing only (CHECKed).
void AppendUff58(const Uff58Record& record, bool binary, std::string* out);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_TRACES_UFF58_H_
