#include "dwellfit/estimator/matfile/mat_sweeps.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <matio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/data/sweep_csv.h"
#include "dwellfit/estimator/matfile/mat_handles.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

// A variable: numbers (a double vector) or texts (a cell array of char).
struct Column {
  std::string name;
  std::vector<double> numbers;
  std::vector<std::string> texts;
  bool text = false;
};

MatVar CharVar(const std::string& text) {
  std::size_t dims[2] = {1, text.size()};
  return MatVar{
      Mat_VarCreate(nullptr, MAT_C_CHAR, MAT_T_UTF8, 2, dims, const_cast<char*>(text.data()), 0)};
}

// The texts as a char matrix, one row each, padded with spaces (MATLAB's char).
MatVar CharMatrix(const std::string& name, const std::vector<std::string>& texts) {
  std::size_t width = 0;
  for (const std::string& text : texts) width = std::max(width, text.size());
  std::string chars(texts.size() * width, ' ');
  for (std::size_t i = 0; i < texts.size(); ++i) {
    for (std::size_t k = 0; k < texts[i].size(); ++k) chars[i + k * texts.size()] = texts[i][k];
  }
  std::size_t dims[2] = {texts.size(), width};
  return MatVar{Mat_VarCreate(name.c_str(), MAT_C_CHAR, MAT_T_UTF8, 2, dims, chars.data(), 0)};
}

MatVar ColumnVar(Column column, bool char_matrix = false) {
  const std::size_t n = column.text ? column.texts.size() : column.numbers.size();
  if (column.text && char_matrix) return CharMatrix(column.name, column.texts);
  std::size_t dims[2] = {n, 1};
  if (!column.text) {
    return MatVar{Mat_VarCreate(column.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                                column.numbers.data(), 0)};
  }
  MatVar cell{Mat_VarCreate(column.name.c_str(), MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0)};
  for (std::size_t i = 0; i < n; ++i) {
    Mat_VarSetCell(cell.get(), static_cast<int>(i), CharVar(column.texts[i]).release());
  }
  return cell;
}

// Writes `variables` into a fresh MAT file of `version`; returns its path.
std::string WriteMat(const std::string& name, const std::vector<MatVar>& variables,
                     mat_ft version = MAT_FT_MAT5) {
  const std::string path = ::testing::TempDir() + "dwellfit_mat_sweeps_" + name + ".mat";
  std::remove(path.c_str());
  MatFile mat{Mat_CreateVer(path.c_str(), nullptr, version)};
  EXPECT_TRUE(mat) << "cannot create " << path;
  for (const MatVar& var : variables) {
    EXPECT_EQ(Mat_VarWrite(mat.get(), var.get(), MAT_COMPRESSION_NONE), 0) << var->name;
  }
  return path;
}

// The columns of a sweeps CSV without quoted fields (the datasets' files).
std::vector<Column> CsvColumns(const std::string& csv_path) {
  std::ifstream in(csv_path);
  std::vector<Column> columns;
  std::string line;
  for (bool header = true; std::getline(in, line); header = false) {
    std::istringstream fields(line);
    std::string field;
    for (std::size_t i = 0; std::getline(fields, field, ','); ++i) {
      if (header) {
        columns.push_back({field, {}, {}, field == "sweep" || field == "direction"});
      } else if (columns[i].text) {
        columns[i].texts.push_back(field);
      } else {
        columns[i].numbers.push_back(std::strtod(field.c_str(), nullptr));  // correctly rounded
      }
    }
  }
  return columns;
}

std::vector<MatVar> Vars(const std::vector<Column>& columns, bool char_matrix = false) {
  std::vector<MatVar> vars;
  for (const Column& column : columns) vars.push_back(ColumnVar(column, char_matrix));
  return vars;
}

// A small valid table; tests break one thing in it.
std::vector<Column> SmallTable() {
  return {{"sweep", {}, {"F1", "F1", "F1"}, true},
          {"direction", {}, {"up", "up", "up"}, true},
          {"freq_hz", {40.0, 40.5, 41.0}},
          {"a_base", {0.01, 0.01, 0.01}},
          {"a", {1e-4, 2e-4, 1.5e-4}}};
}

std::string LoadError(const std::string& path) {
  try {
    LoadSweepsMat(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no error)";
}

struct Case {
  const char* dataset;
  mat_ft version;
  bool char_matrix;  // the ids as char matrices, else as cell arrays
};

class MatSweepsEqualCsvTest : public testing::TestWithParam<Case> {};

// The MAT file holding a dataset's CSV columns loads to the CSV's sweeps,
// value for value (the rows' lines are the rows' numbers, one less).
TEST_P(MatSweepsEqualCsvTest, LoadsTheSweepsOfTheCsv) {
  const std::string csv =
      std::string(DWELLFIT_SOURCE_DIR) + "/datasets/" + GetParam().dataset + "/sweeps.csv";
  const std::string mat =
      WriteMat(std::string(GetParam().dataset) + "_" + std::to_string(GetParam().version) +
                   (GetParam().char_matrix ? "_char" : "_cell"),
               Vars(CsvColumns(csv), GetParam().char_matrix), GetParam().version);
  const LoadedSweeps from_csv = LoadSweepsCsv(csv);
  const LoadedSweeps from_mat = LoadSweepsMat(mat);
  ASSERT_EQ(from_mat.sweeps.size(), from_csv.sweeps.size());
  EXPECT_EQ(from_mat.dropped_nonpositive, from_csv.dropped_nonpositive);
  for (std::size_t s = 0; s < from_csv.sweeps.size(); ++s) {
    const Sweep& expected = from_csv.sweeps[s];
    const Sweep& actual = from_mat.sweeps[s];
    EXPECT_EQ(actual.Name(), expected.Name());
    EXPECT_EQ(actual.kind, expected.kind);
    EXPECT_EQ(actual.source_file, mat);
    ASSERT_EQ(actual.points.size(), expected.points.size()) << expected.Name();
    for (std::size_t i = 0; i < expected.points.size(); ++i) {
      const DwellPoint& e = expected.points[i];
      const DwellPoint& a = actual.points[i];
      EXPECT_EQ(a.drive_frequency_rad_s, e.drive_frequency_rad_s);
      EXPECT_EQ(a.a_base, e.a_base);
      EXPECT_EQ(a.amplitude, e.amplitude);
      EXPECT_EQ(a.phase_rad, e.phase_rad);
      EXPECT_EQ(a.sigma, e.sigma);
      EXPECT_EQ(a.a_base_sigma, e.a_base_sigma);
      EXPECT_EQ(a.source_line, e.source_line - 1);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Datasets, MatSweepsEqualCsvTest,
                         testing::Values(Case{"thesis-numerical", MAT_FT_MAT5, false},
                                         Case{"thesis-numerical", MAT_FT_MAT73, true},
                                         Case{"thesis-numerical", MAT_FT_MAT5, true},
                                         Case{"clamped-beam-27C", MAT_FT_MAT5, false},
                                         // libmatio reads a v7.3 cell array in time
                                         // growing as its length squared (docs/matlab.md)
                                         Case{"clamped-beam-27C", MAT_FT_MAT73, true}));

// (libmatio reads a v7.3 cell array of 456 ids in 0.4 s, and would take some
// 50 minutes for 24,576: the datasets are tested in v7.3 with char matrices.)
TEST(MatSweepsTest, ASmallTableOfCellArraysLoadsInV73) {
  const LoadedSweeps loaded = LoadSweepsMat(WriteMat("small73", Vars(SmallTable()), MAT_FT_MAT73));
  ASSERT_EQ(loaded.sweeps.size(), 1u);
  EXPECT_EQ(loaded.sweeps[0].Name(), "F1/up");
  EXPECT_EQ(loaded.sweeps[0].points[2].amplitude, 1.5e-4);
}

// v7.3 files are read by HDF5 in a child process (child_process.h): a damaged
// one is refused with a message, whatever HDF5 makes of it, and the caller
// goes on. Each cut of a good v7.3 file, and each with a byte flipped, must
// load or be refused; none may end the test.
TEST(MatSweepsTest, DamagedV73FilesAreRefusedAndTheCallerGoesOn) {
  const std::string good = WriteMat("damaged73", Vars(SmallTable()), MAT_FT_MAT73);
  std::ifstream stream(good, std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(stream), {});
  ASSERT_GT(bytes.size(), 1024u);
  const std::string path = ::testing::TempDir() + "dwellfit_mat_sweeps_damaged73_cut.mat";
  int refused = 0;
  for (std::size_t size = 512; size < bytes.size(); size += bytes.size() / 16) {
    std::ofstream(path, std::ios::binary) << bytes.substr(0, size);
    const std::string error = LoadError(path);
    if (error == "(no error)") continue;
    EXPECT_THAT(error, HasSubstr(path + ": ")) << "cut at " << size;
    ++refused;
  }
  EXPECT_GT(refused, 0);
  for (std::size_t at = 512; at < bytes.size(); at += 97) {
    std::string flipped = bytes;
    flipped[at] = static_cast<char>(~flipped[at]);
    std::ofstream(path, std::ios::binary) << flipped;
    try {
      LoadSweepsMat(path);
    } catch (const InputError& error) {
      EXPECT_THAT(error.what(), HasSubstr(path + ": ")) << "flipped at " << at;
    }
  }
}

TEST(MatSweepsTest, NotAMatFile) {
  const std::string path = ::testing::TempDir() + "dwellfit_mat_sweeps_text.mat";
  std::ofstream(path) << "sweep,direction,freq_hz,a_base,a\nF1,up,40,0.01,1e-4\n";
  EXPECT_THAT(LoadError(path),
              HasSubstr(path + ": is not a MAT file that libmatio reads (v5, v7 or v7.3)"));
}

// A v5 file whose first variable claims 2 GB (libmatio would allocate them).
TEST(MatSweepsTest, DamagedFile) {
  const std::string path = WriteMat("damaged", Vars(SmallTable()));
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(128 + 4);  // the first element's byte count, after the 128-byte header
  file.write("\xFF\xFF\xFF\x7F", 4);
  file.close();
  EXPECT_THAT(LoadError(path),
              HasSubstr(path + ": the file is damaged (an element claims more bytes than the file "
                               "gives it); save it again"));
}

// The level's standard deviation, a_base_sigma, loads like the CSV column:
// the same double, in v5 and v7.3.
TEST(MatSweepsTest, LevelSigmaLoadsAsTheSameDouble) {
  const double level_sigma = 0.005 * 0.01 / std::sqrt(3.0);
  std::vector<Column> table = SmallTable();
  table.push_back({"a_base_sigma", {level_sigma, level_sigma, level_sigma}});
  for (mat_ft version : {MAT_FT_MAT5, MAT_FT_MAT73}) {
    const LoadedSweeps loaded =
        LoadSweepsMat(WriteMat("level_sigma_" + std::to_string(version), Vars(table), version));
    ASSERT_EQ(loaded.sweeps.size(), 1u);
    ASSERT_EQ(loaded.sweeps[0].points.size(), 3u);
    for (const DwellPoint& point : loaded.sweeps[0].points) {
      ASSERT_TRUE(point.a_base_sigma.has_value()) << version;
      EXPECT_EQ(*point.a_base_sigma, level_sigma) << version;
    }
  }
}

TEST(MatSweepsTest, LevelSigmaIsCheckedLikeTheCsvColumnAndNamesItsRow) {
  std::vector<Column> table = SmallTable();
  table.push_back({"a_base_sigma", {2e-5, 2e-5, 0.0}});
  std::string path = WriteMat("level_sigma_zero", Vars(table));
  EXPECT_THAT(LoadError(path), HasSubstr(path + ": variable 'a_base_sigma', row 3: the standard "
                                                "deviation a_base_sigma must be > 0, got 0"));
  table.back().numbers = {2e-5, 2e-5, 3e-5};
  path = WriteMat("level_sigma_differs", Vars(table));
  EXPECT_THAT(LoadError(path),
              HasSubstr(path + ": variable 'a_base_sigma', row 3: sweep 'F1/up' is a frequency "
                               "sweep (one level a_base), but its a_base_sigma changes from "
                               "2e-05 (row 1) to 3e-05"));
}

TEST(MatSweepsTest, MissingVariable) {
  std::vector<Column> table = SmallTable();
  table.pop_back();
  const std::string path = WriteMat("missing", Vars(table));
  EXPECT_THAT(LoadError(path), HasSubstr(path + ": variable 'a': is missing; a sweeps MAT file"));
}

TEST(MatSweepsTest, UnknownVariable) {
  std::vector<Column> table = SmallTable();
  table.push_back({"Sigma", {1e-6, 1e-6, 1e-6}});
  EXPECT_THAT(LoadError(WriteMat("unknown", Vars(table))),
              HasSubstr("variable 'Sigma': unknown variable; a sweeps MAT file holds"));
}

TEST(MatSweepsTest, WrongClassOfNumbers) {
  std::vector<MatVar> vars = Vars(SmallTable());
  std::int32_t levels[3] = {1, 1, 1};
  std::size_t dims[2] = {3, 1};
  vars[3].reset(Mat_VarCreate("a_base", MAT_C_INT32, MAT_T_INT32, 2, dims, levels, 0));
  EXPECT_THAT(LoadError(WriteMat("int32", vars)),
              HasSubstr("variable 'a_base': is not a real double array; give the numbers as "
                        "doubles (double(x) in MATLAB"));
}

TEST(MatSweepsTest, IdsAsACharMatrixLoseTheirPadding) {
  std::vector<Column> table = SmallTable();
  table[0].texts = {"F1", "F1", "A10"};  // "F1 " padded
  table[1].texts = {"up", "up", "down"};
  const LoadedSweeps loaded = LoadSweepsMat(WriteMat("char", Vars(table, true)));
  ASSERT_EQ(loaded.sweeps.size(), 2u);
  EXPECT_EQ(loaded.sweeps[0].Name(), "F1/up");
  EXPECT_EQ(loaded.sweeps[1].Name(), "A10/down");
}

TEST(MatSweepsTest, WrongClassOfText) {
  std::vector<Column> table = SmallTable();
  table[0] = {"sweep", {1.0, 1.0, 1.0}};
  EXPECT_THAT(LoadError(WriteMat("text_class", Vars(table))),
              HasSubstr("variable 'sweep': is neither a cell array nor a char matrix; give a "
                        "cell array of char strings"));
}

TEST(MatSweepsTest, LengthsDiffer) {
  std::vector<Column> table = SmallTable();
  table[4].numbers.pop_back();
  EXPECT_THAT(LoadError(WriteMat("lengths", Vars(table))),
              HasSubstr("variable 'a': has 2 values but sweep has 3; give every variable one "
                        "value per row"));
}

TEST(MatSweepsTest, NonFiniteValueNamesItsRow) {
  std::vector<Column> table = SmallTable();
  table[4].numbers[2] = std::numeric_limits<double>::quiet_NaN();
  const std::string path = WriteMat("nan", Vars(table));
  EXPECT_THAT(LoadError(path),
              HasSubstr(path + ": variable 'a', row 3: value 'nan' is not finite (NaN or "
                               "infinity); give a measured number or drop the row"));
}

TEST(MatSweepsTest, RowChecksOfTheCsvNameRows) {
  std::vector<Column> table = SmallTable();
  table[2].numbers = {40.0, 41.0, 40.5};  // an up-sweep falling
  EXPECT_THAT(LoadError(WriteMat("order", Vars(table))),
              HasSubstr("variable 'freq_hz', row 3: sweep 'F1/up' is an up-sweep, but freq_hz "
                        "falls from 41 (row 2) to 40.5"));
}

TEST(MatSweepsTest, MatrixInsteadOfVector) {
  std::vector<MatVar> vars = Vars(SmallTable());
  double values[6] = {1e-4, 2e-4, 3e-4, 1e-4, 2e-4, 3e-4};
  std::size_t dims[2] = {3, 2};
  vars[4].reset(Mat_VarCreate("a", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, values, 0));
  EXPECT_THAT(LoadError(WriteMat("matrix", vars)),
              HasSubstr("variable 'a': is a 3 x 2 array; give a vector (x(:) in MATLAB)"));
}

}  // namespace
}  // namespace dwellfit
