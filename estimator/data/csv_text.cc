#include "dwellfit/estimator/data/csv_text.h"

#include <algorithm>
#include <charconv>
#include <cstring>

#include "glog/logging.h"

namespace dwellfit {

namespace {

// The most characters std::to_chars writes for a double or a long, and the
// comma after it.
constexpr std::size_t kNumberBytes = 32;

}  // namespace

CsvText::CsvText(std::string_view header, std::size_t expected_bytes) {
  buffer_.resize(std::max<std::size_t>(expected_bytes, header.size() + 1));
  if (header.empty()) return;
  Text(header);
  EndRow();
}

char* CsvText::Room(std::size_t bytes) {
  if (size_ + bytes > buffer_.size()) buffer_.resize(std::max(2 * buffer_.size(), size_ + bytes));
  return buffer_.data() + size_;
}

void CsvText::Text(std::string_view text) {
  char* at = Room(text.size() + 1);
  std::memcpy(at, text.data(), text.size());
  at[text.size()] = ',';
  size_ += text.size() + 1;
}

template <typename T>
void CsvText::Field(T value) {
  char* at = Room(kNumberBytes);
  const std::to_chars_result result = std::to_chars(at, at + kNumberBytes - 1, value);
  CHECK(result.ec == std::errc()) << "31 characters hold any double or long";
  *result.ptr = ',';
  size_ = static_cast<std::size_t>(result.ptr + 1 - buffer_.data());
}

void CsvText::Number(double value) { Field(value); }

void CsvText::Integer(long value) { Field(value); }

void CsvText::Empty() {
  *Room(1) = ',';
  ++size_;
}

void CsvText::EndRow() {
  CHECK(size_ > 0 && buffer_[size_ - 1] == ',') << "a row needs at least one field";
  buffer_[size_ - 1] = '\n';
}

std::string CsvText::Release() && {
  buffer_.resize(size_);
  size_ = 0;
  return std::move(buffer_);
}

}  // namespace dwellfit
