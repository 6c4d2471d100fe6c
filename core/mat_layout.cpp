#include "core/mat_layout.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>

#include <fmt/format.h>

#include "core/input_error.hpp"

namespace hw {
namespace {

// A file's bytes at any offset, and its 32-bit words in the file's byte order (independent of the machine's).
class ByteFile {
 public:
  explicit ByteFile(const std::string& path) : in_(path, std::ios::binary) {
    in_.seekg(0, std::ios::end);
    size_ = in_ ? static_cast<std::uint64_t>(in_.tellg()) : 0;
  }
  std::uint64_t size() const { return size_; }
  void set_big_endian(bool big) { big_endian_ = big; }
  // Up to n bytes at `at` (fewer at the end of the file).
  std::string Bytes(std::uint64_t at, std::uint64_t n) {
    if (at >= size_) return {};
    std::string s(static_cast<std::size_t>(std::min(n, size_ - at)), '\0');
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(s.data(), static_cast<std::streamsize>(s.size()));
    return s;
  }
  std::uint32_t U32(std::uint64_t at) {
    const std::string b = Bytes(at, 4);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < b.size(); ++k)
      v |= static_cast<std::uint32_t>(static_cast<unsigned char>(b[k])) << (8 * (big_endian_ ? 3 - k : k));
    return v;
  }

 private:
  std::ifstream in_;
  std::uint64_t size_ = 0;
  bool big_endian_ = false;
};

[[noreturn]] void Damaged(const std::string& path, std::uint64_t at, const std::string& name, const std::string& what) {
  throw InputError(fmt::format("{}: damaged MATLAB file: the variable {}at byte {}: {}; save the file again "
                               "(MATLAB's save, scipy.io.savemat)",
                               path, name.empty() ? "" : "'" + name + "' ", at, what));
}

// The text of a name field: up to its first NUL, at most 63 characters (MATLAB's limit) shown.
std::string NameText(const std::string& bytes) { return bytes.substr(0, std::min<std::size_t>(bytes.find('\0'), 63)); }

// ---------------------------------------------------------------------------------------------------------
// v5: a 128-byte header, then elements, each an 8-byte tag (type, bytes) and its data padded to 8 bytes; a
// small element keeps up to 4 bytes of data in its tag. A variable is an miMATRIX element (array flags,
// dimensions, name, real part, ...) or an miCOMPRESSED element holding one, deflated.

constexpr std::uint32_t kMiInt32 = 5, kMiMatrix = 14, kMiCompressed = 15;

struct Tag {
  std::uint32_t type = 0;
  std::uint64_t size = 0;  // bytes of data
  std::uint64_t data = 0;  // offset of the data
  std::uint64_t next = 0;  // offset after the element
};

Tag ReadTag(ByteFile& f, std::uint64_t at) {
  const std::uint32_t first = f.U32(at);
  if (first >> 16) return {first & 0xffff, first >> 16, at + 4, at + 8};  // small element
  const std::uint64_t n = f.U32(at + 4);
  return {first, n, at + 8, at + 8 + (n + 7) / 8 * 8};
}

// Bytes per value of a v5 numeric data type (miINT8 = 1 ... miUINT64 = 13); 0 for any other type.
std::uint64_t DataTypeBytes(std::uint32_t type) {
  switch (type) {
    case 1: case 2: return 1;            // miINT8, miUINT8
    case 3: case 4: return 2;            // miINT16, miUINT16
    case 5: case 6: case 7: return 4;    // miINT32, miUINT32, miSINGLE
    case 9: case 12: case 13: return 8;  // miDOUBLE, miINT64, miUINT64
    default: return 0;
  }
}

bool IsNumericArrayClass(std::uint32_t array_class) { return array_class >= 6 && array_class <= 15; }  // double..uint64

// An uncompressed variable whose data span [at, end) (`end_text` says what ends there): its parts lie inside, and
// a numeric array's real part holds exactly the values its dimensions claim.
void CheckMatrix(ByteFile& f, const std::string& path, std::uint64_t at, std::uint64_t end, const char* end_text) {
  if (at == end) return;  // an empty element: an empty array
  std::string name;
  std::uint64_t pos = at;
  auto part = [&](const char* what) {
    if (pos + 8 > end) Damaged(path, at - 8, name, fmt::format("its {} would start past the end of {}", what, end_text));
    const Tag t = ReadTag(f, pos);
    if (t.data + t.size > end)
      Damaged(path, at - 8, name, fmt::format("its {} ({} bytes) run past the end of {}", what, t.size, end_text));
    pos = t.next;
    return t;
  };
  const Tag flags = part("array flags");
  const std::uint32_t array_class = flags.size >= 4 ? f.U32(flags.data) & 0xff : 0;
  const Tag dims = part("dimensions");
  if (dims.type != kMiInt32 || dims.size < 8 || dims.size % 4 != 0)
    Damaged(path, at - 8, name, "its dimensions are not two or more 32-bit integers");
  double elements = 1;
  std::string shape;
  for (std::uint64_t k = 0; k < dims.size / 4; ++k) {
    const auto d = static_cast<std::int32_t>(f.U32(dims.data + 4 * k));
    if (d < 0) Damaged(path, at - 8, name, fmt::format("dimension {} is negative ({})", k + 1, d));
    elements *= d;
    shape += fmt::format("{}{}", k ? "x" : "", d);
  }
  name = NameText(f.Bytes(part("name").data, 64));
  if (!IsNumericArrayClass(array_class)) return;  // the reader refuses it by its class (core/mat_recording.cpp)
  const Tag real = part("data");
  const std::uint64_t bytes = DataTypeBytes(real.type);
  if (bytes == 0) Damaged(path, at - 8, name, fmt::format("its data have the type code {}, which holds no numbers", real.type));
  if (static_cast<double>(real.size) != elements * static_cast<double>(bytes))
    Damaged(path, at - 8, name,
            fmt::format("it is {} but its data hold {} values ({} bytes)", shape, real.size / bytes, real.size));
}

// ---------------------------------------------------------------------------------------------------------
// v4: variables one after another, each a 20-byte header (type MOPT, rows, columns, imaginary flag, name
// length), the name, then the data (real part, then imaginary part).

constexpr std::uint32_t kMaxV4Type = 4052;  // M <= 4, O = 0, P <= 5, T <= 2

bool ValidV4Type(std::uint32_t type) {
  return type <= kMaxV4Type && type / 100 % 10 == 0 && type / 10 % 10 <= 5 && type % 10 <= 2;
}

}  // namespace

int MatHeaderVersion(const std::string& path) {
  ByteFile f(path);
  const std::string b = f.Bytes(124, 4);
  if (b.size() < 4) return 0;
  const auto byte = [&](int k) { return static_cast<int>(static_cast<unsigned char>(b[k])); };
  if (b.substr(2) == "IM") return byte(0) | byte(1) << 8;  // written little-endian
  if (b.substr(2) == "MI") return byte(0) << 8 | byte(1);  // written big-endian
  return 0;
}

void CheckMatV5Layout(const std::string& path) {
  ByteFile f(path);
  if (f.size() < 128) return;  // no header: libmatio has refused the file
  f.set_big_endian(f.Bytes(126, 2) == "MI");
  for (std::uint64_t at = 128; at < f.size();) {
    const std::uint64_t left = f.size() - at;
    if (left < 8) {
      if (f.Bytes(at, left).find_first_not_of('\0') == std::string::npos) return;  // zero padding at the end
      Damaged(path, at, "", fmt::format("the file ends {} bytes into its 8-byte tag", left));
    }
    const Tag t = ReadTag(f, at);
    const bool cut = t.data + t.size > f.size();
    if (t.type == kMiMatrix)  // names the variable and what of it is missing when the file is cut short
      CheckMatrix(f, path, t.data, std::min(t.data + t.size, f.size()), cut ? "the file (cut short)" : "the variable");
    if (cut) Damaged(path, at, "", fmt::format("it needs {} bytes but the file ends after {}", t.data + t.size - at, left));
    at = t.type == kMiCompressed ? t.data + t.size : t.next;
  }
}

void CheckMatV4Layout(const std::string& path) {
  static const std::uint64_t kValueBytes[] = {8, 4, 4, 2, 2, 1};  // by P: double, single, int32, int16, uint16, uint8
  ByteFile f(path);
  // A header that is wrong at the first variable: the file is no .mat file at all (or not one of these formats).
  auto bad_header = [&path](std::uint64_t at, const std::string& what) {
    if (at > 0) Damaged(path, at, "", what);
    throw InputError(fmt::format("{}: not a MATLAB .mat file: no v5 or v7.3 header, and no v4 variable at its start "
                                 "({}); save it with MATLAB's save(...) or scipy.io.savemat",
                                 path, what));
  };
  for (std::uint64_t at = 0; at < f.size();) {
    const std::uint64_t left = f.size() - at;
    if (left < 20) bad_header(at, fmt::format("the file ends {} bytes into a 20-byte v4 header", left));
    f.set_big_endian(false);
    if (!ValidV4Type(f.U32(at))) f.set_big_endian(true);
    const std::uint32_t type = f.U32(at);
    if (!ValidV4Type(type)) bad_header(at, fmt::format("its type code {} is not a MATLAB v4 type", type));
    const auto rows = static_cast<std::int32_t>(f.U32(at + 4)), columns = static_cast<std::int32_t>(f.U32(at + 8));
    const bool complex = f.U32(at + 12) != 0;
    const std::uint64_t name_bytes = f.U32(at + 16);
    if (name_bytes == 0 || name_bytes > left - 20)
      bad_header(at, fmt::format("its name length {} does not fit the file", name_bytes));
    const std::string name = NameText(f.Bytes(at + 20, std::min<std::uint64_t>(name_bytes, 64)));
    if (rows < 0 || columns < 0) Damaged(path, at, name, fmt::format("its dimensions {}x{} are negative", rows, columns));
    const double data = static_cast<double>(rows) * columns * kValueBytes[type / 10 % 10] * (complex ? 2 : 1);
    if (data > static_cast<double>(left - 20 - name_bytes))
      Damaged(path, at, name, fmt::format("it is {}x{} ({} bytes of data) but the file ends after {}", rows, columns,
                                          data, left - 20 - name_bytes));
    at += 20 + name_bytes + static_cast<std::uint64_t>(data);
  }
}

}  // namespace hw
