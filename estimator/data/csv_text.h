// The text of a large CSV file, built row by row in one buffer.
//
// Numbers are written by std::to_chars (the shortest text that reads back as
// the same double), straight into the end of one growing buffer.
//
//   CsvText csv("sweep,freq_hz,a", rows * 40);
//   csv.Text("F1");
//   csv.Number(155.0);
//   csv.Number(3.2e-05);
//   csv.EndRow();                     // "F1,155,3.2e-05\n"
//   std::string text = std::move(csv).Release();
#ifndef DWELLFIT_ESTIMATOR_DATA_CSV_TEXT_H_
#define DWELLFIT_ESTIMATOR_DATA_CSV_TEXT_H_

#include <cstddef>
#include <string>
#include <string_view>

namespace dwellfit {

class CsvText {
 public:
  // Starts with the `header` line (given without its line end), when not
  // empty; `expected_bytes` is the whole text's likely length, reserved at
  // once (more is still fine).
  CsvText(std::string_view header, std::size_t expected_bytes);

  // One field of the current row each; fields are separated by commas. The
  // caller keeps commas, quotes and line ends out of `text`.
  void Text(std::string_view text);
  void Number(double value);  // shortest round trip; NaN and inf as "nan", "inf"
  void Integer(long value);
  void Empty();
  // Ends the current row (with at least one field) with a line end.
  void EndRow();

  // The text; the CsvText is empty afterwards.
  std::string Release() &&;

 private:
  // Room for `bytes` more characters at the end; returns where they go.
  char* Room(std::size_t bytes);
  // One field of std::to_chars' text of `value` (a double or a long).
  template <typename T>
  void Field(T value);

  std::string buffer_;    // its first size_ characters are the text
  std::size_t size_ = 0;  // every field ends with a comma, which EndRow() turns into the line end
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_DATA_CSV_TEXT_H_
