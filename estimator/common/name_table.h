// An enum's words (in config files, CSV columns and reports) as one table of
// names in enumerator order, looked up both ways.
#ifndef DWELLFIT_ESTIMATOR_COMMON_NAME_TABLE_H_
#define DWELLFIT_ESTIMATOR_COMMON_NAME_TABLE_H_

#include <cstddef>
#include <string>

namespace dwellfit {

// names[value]: `names` holds one name per enumerator, in enumerator order
// from 0. A value outside the table (a bug) reads "?", never past the table.
template <typename Enum, size_t N>
const char* NameOf(const char* const (&names)[N], Enum value) {
  const auto index = static_cast<size_t>(value);
  return index < N ? names[index] : "?";
}

// The enumerator whose name is `name`: true and *value set, or false with
// *value untouched when `names` has no such entry.
template <typename Enum, size_t N>
bool FromName(const std::string& name, const char* const (&names)[N], Enum* value) {
  for (size_t i = 0; i < N; ++i) {
    if (name == names[i]) {
      *value = static_cast<Enum>(i);
      return true;
    }
  }
  return false;
}

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_COMMON_NAME_TABLE_H_
