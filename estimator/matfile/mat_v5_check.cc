#include "dwellfit/estimator/matfile/mat_v5_check.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <string>

namespace dwellfit {
namespace {

// v5 data types and array classes (MATLAB's "MAT-File Format", 2-9, 1-16).
constexpr std::uint32_t kMiMatrix = 14, kMiCompressed = 15;
constexpr std::uint32_t kCell = 1, kChar = 4, kDouble = 6, kLastNumeric = 15;

struct Bytes {
  const unsigned char* data;
  bool swap;  // big-endian file
  std::uint32_t U32(std::size_t at) const {
    const unsigned char* p = data + at;
    return swap ? std::uint32_t{p[0]} << 24 | p[1] << 16 | p[2] << 8 | p[3]
                : std::uint32_t{p[3]} << 24 | p[2] << 16 | p[1] << 8 | p[0];
  }
};

std::string CheckMatrix(const Bytes& bytes, std::size_t at, std::size_t end, int depth);

// Reads the tag at `*at` (inside [.., end)): its type, and the span of its
// data; moves `*at` past the element (padded to 8 bytes). "" or what is wrong.
std::string NextElement(const Bytes& bytes, std::size_t* at, std::size_t end, std::uint32_t* type,
                        std::size_t* data, std::size_t* size) {
  if (end - *at < 8) return "an element's tag is cut off";
  *type = bytes.U32(*at);
  if (*type >> 16 != 0) {  // small element: up to 4 bytes inside the tag
    *size = *type >> 16;
    *type &= 0xFFFF;
    *data = *at + 4;
    *at += 8;
    return *size <= 4 ? "" : "a small element holds more than 4 bytes";
  }
  *size = bytes.U32(*at + 4);
  *data = *at + 8;
  if (*size > end - *data) return "an element claims more bytes than the file gives it";
  const std::size_t padded = *type == kMiCompressed ? *size : (*size + 7) / 8 * 8;
  *at = *data + std::min(padded, end - *data);
  return "";
}

// The miMATRIX elements inside a cell array of `count` elements.
std::string CheckCells(const Bytes& bytes, std::size_t at, std::size_t end, double count,
                       int depth) {
  if (depth > 0) return "a cell array inside a cell array";
  if (count * 8 > static_cast<double>(end - at)) return "a cell array claims more elements";
  for (double i = 0; i < count; ++i) {
    std::uint32_t type = 0;
    std::size_t data = 0, size = 0;
    if (std::string e = NextElement(bytes, &at, end, &type, &data, &size); !e.empty()) return e;
    if (type != kMiMatrix) return "a cell holds no array";
    if (std::string e = CheckMatrix(bytes, data, data + size, depth + 1); !e.empty()) return e;
  }
  return "";
}

// An array: flags, dimensions, name, then its cells or values.
std::string CheckMatrix(const Bytes& bytes, std::size_t at, std::size_t end, int depth) {
  std::uint32_t type[3] = {};
  std::size_t data[3] = {}, size[3] = {};
  for (int i = 0; i < 3; ++i) {
    if (std::string e = NextElement(bytes, &at, end, &type[i], &data[i], &size[i]); !e.empty()) {
      return e;
    }
  }
  if (size[0] < 8 || size[1] < 8 || size[1] % 4 != 0) return "an array's header is damaged";
  const std::uint32_t array_class = bytes.U32(data[0]) & 0xFF;
  double count = 1;
  for (std::size_t d = 0; d < size[1]; d += 4) count *= bytes.U32(data[1] + d);
  if (array_class == kCell) return CheckCells(bytes, at, end, count, depth);
  if (array_class != kChar && (array_class < kDouble || array_class > kLastNumeric)) {
    return "an array of a class a sweeps file does not use (struct, sparse, object, ...)";
  }
  std::uint32_t value_type = 0;
  std::size_t values = 0, value_bytes = 0;
  if (at >= end) return count == 0 ? "" : "an array's values are missing";
  if (std::string e = NextElement(bytes, &at, end, &value_type, &values, &value_bytes);
      !e.empty()) {
    return e;
  }
  return count <= static_cast<double>(value_bytes) ? "" : "an array claims more values";
}

// The inflated bytes of a miCOMPRESSED element, at most `limit` of them.
bool Inflate(const unsigned char* data, std::size_t size, std::size_t limit, std::string* out) {
  z_stream stream{};
  if (inflateInit(&stream) != Z_OK) return false;
  stream.next_in = const_cast<unsigned char*>(data);
  stream.avail_in = static_cast<uInt>(size);
  int status = Z_OK;
  while (status == Z_OK && out->size() < limit) {
    const std::size_t have = out->size();
    out->resize(std::min(limit, have * 2 + 4096));
    stream.next_out = reinterpret_cast<unsigned char*>(out->data() + have);
    stream.avail_out = static_cast<uInt>(out->size() - have);
    status = inflate(&stream, Z_NO_FLUSH);
    out->resize(out->size() - stream.avail_out);
  }
  inflateEnd(&stream);
  return status == Z_STREAM_END;
}

// The header's version: 0x0100 (v5) or 0x0200 (v7.3); 0 for no header.
unsigned Version(const std::string& file) {
  if (file.size() < 128) return 0;
  const auto byte = [&file](std::size_t at) { return static_cast<unsigned char>(file[at]); };
  if (file.compare(126, 2, "IM") == 0) return byte(125) << 8 | byte(124);
  if (file.compare(126, 2, "MI") == 0) return byte(124) << 8 | byte(125);
  return 0;
}

}  // namespace

bool HasMatHeader(const std::string& file) {
  return Version(file) == 0x0100 || Version(file) == 0x0200;
}

bool IsMatV73(const std::string& file) { return Version(file) == 0x0200; }

std::string CheckMatV5(const std::string& file) {
  if (Version(file) != 0x0100) return "";  // not v5
  const Bytes bytes{reinterpret_cast<const unsigned char*>(file.data()), file[126] == 'M'};
  for (std::size_t at = 128; at < file.size();) {
    std::uint32_t type = 0;
    std::size_t data = 0, size = 0;
    if (std::string e = NextElement(bytes, &at, file.size(), &type, &data, &size); !e.empty()) {
      return e;
    }
    std::string inflated;
    if (type == kMiCompressed) {
      // zlib inflates at most 1032-fold.
      if (!Inflate(bytes.data + data, size, 1032 * size + 64, &inflated)) {
        return "a compressed variable does not inflate";
      }
      std::size_t inner = 0;
      const Bytes inner_bytes{reinterpret_cast<const unsigned char*>(inflated.data()), bytes.swap};
      if (std::string e = NextElement(inner_bytes, &inner, inflated.size(), &type, &data, &size);
          !e.empty()) {
        return e;
      }
      if (type != kMiMatrix) return "a compressed element holds no array";
      if (std::string e = CheckMatrix(inner_bytes, data, data + size, 0); !e.empty()) return e;
    } else if (type == kMiMatrix) {
      if (std::string e = CheckMatrix(bytes, data, data + size, 0); !e.empty()) return e;
    }
  }
  return "";
}

}  // namespace dwellfit
