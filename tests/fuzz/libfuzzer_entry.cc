// libFuzzer's entry points for one target: compiled once per fuzzer
// executable with DWELLFIT_FUZZ_BODY naming its body (fuzz_targets.h).
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_targets.h"

#ifndef DWELLFIT_FUZZ_BODY
#error "compile with -DDWELLFIT_FUZZ_BODY=<body function of fuzz_targets.h>"
#endif

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  dwellfit::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  dwellfit::fuzz::DWELLFIT_FUZZ_BODY(data, size);
  return 0;
}
