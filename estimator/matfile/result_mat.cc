#include "dwellfit/estimator/matfile/result_mat.h"

#include <glog/logging.h>
#include <matio.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/matfile/mat_handles.h"

namespace dwellfit {
namespace {

constexpr char kHeader[] = "MATLAB 5.0 MAT-file, written by dwellfit (docs/matlab.md)";

// `name` as a MATLAB identifier not yet in `taken` (see the header).
std::string ValidName(const std::string& name, std::set<std::string>* taken) {
  std::string valid;
  for (char c : name) valid += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (valid.empty() || !std::isalpha(static_cast<unsigned char>(valid[0]))) valid = "x" + valid;
  valid.resize(std::min<std::size_t>(valid.size(), 63));
  std::string unique = valid;
  for (int n = 2; !taken->insert(unique).second; ++n) unique = valid + "_" + std::to_string(n);
  return unique;
}

// The whole of `text` as a double (YAML's .nan and .inf included).
std::optional<double> Number(const std::string& text) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (text == ".nan" || text == ".NaN" || text == "nan")
    return std::numeric_limits<double>::quiet_NaN();
  if (text == ".inf" || text == "+.inf" || text == "inf") return kInf;
  if (text == "-.inf" || text == "-inf") return -kInf;
  const char* begin = text.data() + (text.size() > 1 && text[0] == '+' ? 1 : 0);
  double value = 0.0;
  const auto [end, error] = std::from_chars(begin, text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || begin == end) return std::nullopt;
  return value;
}

MatVar Doubles(const char* name, std::vector<double> values, bool column) {
  std::size_t dims[2] = {column ? values.size() : 1, 1};
  return MatVar{Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, values.data(), 0)};
}

MatVar Text(const char* name, const std::string& text) {
  std::size_t dims[2] = {text.empty() ? 0u : 1u, text.size()};
  return MatVar{
      Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UTF8, 2, dims, const_cast<char*>(text.data()), 0)};
}

MatVar Cell(const char* name, std::vector<MatVar> elements) {
  std::size_t dims[2] = {elements.size(), 1};
  MatVar cell{Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0)};
  for (std::size_t i = 0; i < elements.size(); ++i) {
    Mat_VarSetCell(cell.get(), static_cast<int>(i), elements[i].release());
  }
  return cell;
}

// A struct of the given fields (names made valid and unique).
MatVar Struct(const char* name, std::vector<std::pair<std::string, MatVar>> fields) {
  std::set<std::string> taken;
  std::vector<std::string> names;
  for (const auto& field : fields) names.push_back(ValidName(field.first, &taken));
  std::vector<const char*> pointers;
  for (const std::string& field : names) pointers.push_back(field.c_str());
  std::size_t dims[2] = {1, 1};
  MatVar result{
      Mat_VarCreateStruct(name, 2, dims, pointers.data(), static_cast<unsigned>(pointers.size()))};
  for (std::size_t i = 0; i < fields.size(); ++i) {
    Mat_VarSetStructFieldByName(result.get(), pointers[i], 0, fields[i].second.release());
  }
  return result;
}

MatVar FromYaml(const char* name, const YAML::Node& node);

MatVar FromYamlScalar(const char* name, const YAML::Node& node) {
  const std::string& text = node.Scalar();
  if (node.Tag() != "!") {  // not quoted
    if (const std::optional<double> value = Number(text)) return Doubles(name, {*value}, false);
    if (text == "true" || text == "false") {
      std::uint8_t value = text == "true";
      std::size_t dims[2] = {1, 1};
      return MatVar{Mat_VarCreate(name, MAT_C_UINT8, MAT_T_UINT8, 2, dims, &value, MAT_F_LOGICAL)};
    }
  }
  return Text(name, text);
}

MatVar FromYamlSequence(const char* name, const YAML::Node& node) {
  std::vector<double> numbers;
  bool all_numbers = true, all_text = true;
  for (const YAML::Node& element : node) {
    const bool scalar = element.IsScalar();
    const std::optional<double> value = scalar ? Number(element.Scalar()) : std::nullopt;
    all_numbers = all_numbers && value && element.Tag() != "!";
    all_text = all_text && scalar && !value;
    if (value) numbers.push_back(*value);
  }
  if (all_numbers) return Doubles(name, std::move(numbers), true);
  std::vector<MatVar> elements;
  for (const YAML::Node& element : node) {
    elements.push_back(all_text ? Text(nullptr, element.Scalar()) : FromYaml(nullptr, element));
  }
  return Cell(name, std::move(elements));
}

MatVar FromYaml(const char* name, const YAML::Node& node) {
  if (node.IsMap()) {
    std::vector<std::pair<std::string, MatVar>> fields;
    for (const auto& entry : node) {
      const std::string key = entry.first.as<std::string>();
      fields.emplace_back(key, FromYaml(nullptr, entry.second));
    }
    return Struct(name, std::move(fields));
  }
  if (node.IsSequence()) return FromYamlSequence(name, node);
  if (node.IsScalar()) return FromYamlScalar(name, node);
  return Doubles(name, {}, true);  // null: []
}

// A CSV's text as a struct of column vectors (see the header).
MatVar FromCsv(const char* name, const std::string& csv) {
  std::vector<std::vector<std::string>> columns;
  std::vector<std::string> header;
  std::istringstream lines(csv);
  std::string line;
  for (bool first = true; std::getline(lines, line); first = false) {
    std::vector<std::string> fields(1);
    for (char c : line) {
      if (c == ',') {
        fields.emplace_back();
      } else {
        fields.back().push_back(c);
      }
    }
    if (first) {
      header = fields;
      columns.resize(fields.size());
      continue;
    }
    CHECK_EQ(fields.size(), header.size()) << name << ": a row's fields differ from the header";
    for (std::size_t i = 0; i < fields.size(); ++i) columns[i].push_back(std::move(fields[i]));
  }
  std::vector<std::pair<std::string, MatVar>> fields;
  for (std::size_t i = 0; i < header.size(); ++i) {
    std::vector<double> numbers;
    for (const std::string& field : columns[i]) {
      const std::optional<double> value = Number(field);
      if (!value && !field.empty()) break;
      numbers.push_back(value.value_or(std::numeric_limits<double>::quiet_NaN()));
    }
    std::vector<MatVar> texts;
    if (numbers.size() < columns[i].size()) {
      for (const std::string& field : columns[i]) texts.push_back(Text(nullptr, field));
    }
    fields.emplace_back(header[i], texts.empty() ? Doubles(nullptr, std::move(numbers), true)
                                                 : Cell(nullptr, std::move(texts)));
  }
  return Struct(name, std::move(fields));
}

// A new empty file of the temp directory; its path.
std::string TemporaryFile() {
  std::error_code error;
  const std::filesystem::path directory = std::filesystem::temp_directory_path(error);
  std::string path = (error ? std::filesystem::path("/tmp") : directory) / "dwellfit-XXXXXX.mat";
  const int fd = mkstemps(path.data(), 4);
  if (fd < 0) {
    throw InputError(path, 0, "",
                     std::string("cannot create a temporary file for result.mat (") +
                         std::strerror(errno) + "); set TMPDIR to a writable directory");
  }
  close(fd);
  return path;
}

}  // namespace

std::string ResultMatBytes(const std::string& result_yaml,
                           const std::vector<std::pair<std::string, std::string>>& csv_files) {
  std::vector<MatVar> variables;
  std::set<std::string> taken;
  for (const auto& entry : YAML::Load(result_yaml)) {
    const std::string name = ValidName(entry.first.as<std::string>(), &taken);
    variables.push_back(FromYaml(name.c_str(), entry.second));
  }
  for (const auto& [file, csv] : csv_files) {
    const std::string name =
        ValidName(std::filesystem::path(file).stem().string() + "_csv", &taken);
    variables.push_back(FromCsv(name.c_str(), csv));
  }
  const std::string path = TemporaryFile();
  bool written = false;
  if (MatFile mat{Mat_CreateVer(path.c_str(), kHeader, MAT_FT_MAT5)}) {
    written = true;
    for (const MatVar& var : variables) {
      written = written && var && Mat_VarWrite(mat.get(), var.get(), MAT_COMPRESSION_ZLIB) == 0;
    }
  }
  std::ifstream stream(path, std::ios::binary);
  std::string bytes(std::istreambuf_iterator<char>(stream), {});
  std::remove(path.c_str());
  if (!written) {
    throw InputError(path, 0, "", "cannot write result.mat here; check the temp directory's space");
  }
  return bytes;
}

}  // namespace dwellfit
