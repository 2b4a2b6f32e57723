// A run's result as a MATLAB MAT file (v5, zlib-compressed), result.mat:
// the same names and numbers as result.yaml and the CSVs (docs/matlab.md).
//
//   every top-level key of result.yaml   a variable of that name: a mapping
//       becomes a struct, a list of numbers a double column vector, a list of
//       text a cell column of char strings, any other list a cell column; a
//       number a double, true/false a logical, null [] and text a char string
//   every CSV `<name>.csv`   a struct variable `<name>_csv` of column vectors,
//       one field per column: a double vector when every non-empty field is
//       a number (an empty field is NaN), else a cell column of char strings
// Names that are no MATLAB identifier ("F0.01/up") are made one the way
// matlab.lang.makeValidName does it (each other character becomes '_', a
// leading non-letter gets an 'x' before it); a name taken twice gets _2, _3.
#ifndef DWELLFIT_ESTIMATOR_MATFILE_RESULT_MAT_H_
#define DWELLFIT_ESTIMATOR_MATFILE_RESULT_MAT_H_

#include <string>
#include <utility>
#include <vector>

namespace dwellfit {

// The bytes of result.mat built from `result_yaml` (result.yaml's text) and
// `csv_files` ((file name, CSV text) pairs, each with a header row). The file
// is written through a temporary file of the system's temp directory (libmatio
// writes only to files); throws InputError when that cannot be written.
std::string ResultMatBytes(const std::string& result_yaml,
                           const std::vector<std::pair<std::string, std::string>>& csv_files);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_MATFILE_RESULT_MAT_H_
