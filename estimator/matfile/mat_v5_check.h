// A check of a v5 MAT file's structure before libmatio reads it. libmatio
// allocates what a damaged header claims before it reads the data (a name of
// 4 GB in a 676-byte file took identify to 4.2 GB of memory): here every
// element must lie inside the one that holds it, an array claim no more
// values than its bytes hold, a cell array no more cells, and a compressed
// variable inflate (at most 1032-fold, zlib's limit).
#ifndef DWELLFIT_ESTIMATOR_MATFILE_MAT_V5_CHECK_H_
#define DWELLFIT_ESTIMATOR_MATFILE_MAT_V5_CHECK_H_

#include <string>

namespace dwellfit {

// True when `file` starts with the 128-byte header of a v5 or v7.3 file (the
// version 0x0100 or 0x0200 and the byte-order mark "IM" or "MI"). libmatio
// would read anything else as a v4 file, allocating what its first bytes
// claim (a 25-byte file: 2 GB).
bool HasMatHeader(const std::string& file);

// True when `file` starts with the header of a v7.3 file (version 0x0200):
// an HDF5 file behind a MAT header.
bool IsMatV73(const std::string& file);

// What is wrong with the v5 file whose bytes are `file`; "" when nothing is,
// or when it is no v5 file (v7.3 files are HDF5, which checks its own).
std::string CheckMatV5(const std::string& file);

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_MATFILE_MAT_V5_CHECK_H_
