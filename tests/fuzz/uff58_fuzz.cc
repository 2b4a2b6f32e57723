// Fuzz body of the UFF data set 58 reader (estimator/traces/uff58.h).
#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dwellfit/estimator/common/input_error.h"
#include "dwellfit/estimator/traces/uff58.h"
#include "tests/fuzz/fuzz_targets.h"

namespace dwellfit::fuzz {
namespace {

void Require(bool holds, const std::string& what) {
  if (!holds) throw std::logic_error("ParseUff58: " + what);
}

}  // namespace

void Uff58Body(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  std::vector<Uff58Record> records;
  try {
    records = ParseUff58(bytes, "fuzz.uff");
  } catch (const InputError&) {
    return;
  }
  for (Uff58Record& record : records) {
    // A data set read holds the values its header announces, all finite;
    // one not read holds none.
    Require(record.not_read.empty() || (record.values.empty() && !record.not_read.empty()),
            "values of a data set not read");
    if (!record.not_read.empty()) continue;
    Require(static_cast<std::int64_t>(record.values.size()) == record.value_count,
            "value count differs from record 7");
    for (double value : record.values) Require(std::isfinite(value), "a value is not finite");
    // Written again as binary double precision, it reads back to the same
    // values.
    record.ordinate_data_type = 4;
    std::string again;
    AppendUff58(record, true, &again);
    std::vector<Uff58Record> reread;
    try {
      reread = ParseUff58(again, "again.uff");
    } catch (const InputError& e) {
      Require(false, std::string("cannot read what AppendUff58 wrote: ") + e.what());
    }
    Require(reread.size() == 1 && reread[0].values == record.values &&
                reread[0].ordinate.units == record.ordinate.units &&
                reread[0].response_node == record.response_node,
            "the data set differs after writing and reading again");
  }
}

}  // namespace dwellfit::fuzz
