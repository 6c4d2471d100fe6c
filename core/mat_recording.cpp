#include "core/mat_recording.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>

#include <fmt/format.h>
#include <matio.h>

namespace hw {
namespace {

// libmatio reports problems through a process-wide log function (by default on stderr). Its messages
// are kept here instead and added to ours, so that a bad file gives one clear error and no stray output.
thread_local std::string matio_last_message;

void CaptureMatioLog(int /*level*/, char* message) { matio_last_message = message ? message : ""; }

void InstallMatioLog() {
  static std::once_flag once;
  std::call_once(once, [] { Mat_LogInitFunc("hwbounds", CaptureMatioLog); });
}

std::string MatioDetail() {
  std::string m = matio_last_message;
  matio_last_message.clear();
  return m.empty() ? "" : " (libmatio: " + m + ")";
}

struct VarFree {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using VarPtr = std::unique_ptr<matvar_t, VarFree>;

std::size_t Elements(const matvar_t& v) {
  std::size_t n = 1;
  for (int k = 0; k < v.rank; ++k) n *= v.dims[k];
  return n;
}

std::string Shape(const matvar_t& v) {
  std::string s;
  for (int k = 0; k < v.rank; ++k) s += (k ? "x" : "") + std::to_string(v.dims[k]);
  return s.empty() ? "0x0" : s;
}

std::string ClassName(const matvar_t& v) {
  if (v.isLogical) return "logical";
  switch (v.class_type) {
    case MAT_C_EMPTY: return "empty";
    case MAT_C_CELL: return "cell";
    case MAT_C_STRUCT: return "struct";
    case MAT_C_OBJECT: return "object";
    case MAT_C_CHAR: return "char";
    case MAT_C_SPARSE: return "sparse";
    case MAT_C_DOUBLE: return "double";
    case MAT_C_SINGLE: return "single";
    case MAT_C_INT8: return "int8";
    case MAT_C_UINT8: return "uint8";
    case MAT_C_INT16: return "int16";
    case MAT_C_UINT16: return "uint16";
    case MAT_C_INT32: return "int32";
    case MAT_C_UINT32: return "uint32";
    case MAT_C_INT64: return "int64";
    case MAT_C_UINT64: return "uint64";
    case MAT_C_FUNCTION: return "function handle";
    case MAT_C_OPAQUE: return "opaque object";
  }
  return "unknown class";
}

bool IsNumericClass(matio_classes c) { return c >= MAT_C_DOUBLE && c <= MAT_C_UINT64; }

// Copies the real data of a full numeric variable (its class's C type) into doubles.
template <typename T>
std::vector<double> Convert(const void* data, std::size_t n) {
  const T* p = static_cast<const T*>(data);
  return std::vector<double>(p, p + n);
}

std::vector<double> AsDoubleSamples(const matvar_t& v) {
  const std::size_t n = Elements(v);
  switch (v.class_type) {
    case MAT_C_DOUBLE: return Convert<double>(v.data, n);
    case MAT_C_SINGLE: return Convert<float>(v.data, n);
    case MAT_C_INT8: return Convert<std::int8_t>(v.data, n);
    case MAT_C_UINT8: return Convert<std::uint8_t>(v.data, n);
    case MAT_C_INT16: return Convert<std::int16_t>(v.data, n);
    case MAT_C_UINT16: return Convert<std::uint16_t>(v.data, n);
    case MAT_C_INT32: return Convert<std::int32_t>(v.data, n);
    case MAT_C_UINT32: return Convert<std::uint32_t>(v.data, n);
    case MAT_C_INT64: return Convert<std::int64_t>(v.data, n);
    case MAT_C_UINT64: return Convert<std::uint64_t>(v.data, n);
    default: return {};
  }
}

// An open .mat file, closed on scope exit.
class MatFile {
 public:
  explicit MatFile(const std::string& path) : path_(path) {
    if (std::filesystem::is_directory(path))
      throw InputError(fmt::format("{}: is a directory; expected a MATLAB .mat file", path));
    if (!std::ifstream(path)) throw InputError(fmt::format("{}: cannot open file", path));
    InstallMatioLog();
    matio_last_message.clear();
    mat_ = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
    if (!mat_)
      throw InputError(
          fmt::format("{}: not a MATLAB .mat file that libmatio can read (v4, v5, v7 or v7.3){}; "
                      "save it with MATLAB's save(...) or scipy.io.savemat",
                      path, MatioDetail()));
  }
  ~MatFile() { Mat_Close(mat_); }
  MatFile(const MatFile&) = delete;
  MatFile& operator=(const MatFile&) = delete;

  // Every variable's header (no data), in file order.
  std::vector<VarPtr> Headers() {
    std::vector<VarPtr> out;
    Mat_Rewind(mat_);
    while (matvar_t* v = Mat_VarReadNextInfo(mat_)) out.emplace_back(v);
    return out;
  }

  // "vir (300x1 double), qm (300x1 double)": what the file offers, for messages.
  std::string Listing() {
    std::string s;
    for (const auto& v : Headers())
      s += fmt::format("{}{} ({} {})", s.empty() ? "" : ", ", v->name ? v->name : "?", Shape(*v), ClassName(*v));
    return s.empty() ? "no variables" : s;
  }

  // The variable's samples; throws InputError naming what is wrong with it.
  std::vector<double> ReadVector(const std::string& name) {
    VarPtr info(Mat_VarReadInfo(mat_, name.c_str()));
    matio_last_message.clear();
    if (!info) throw InputError(fmt::format("{}: no variable '{}'; the file has: {}", path_, name, Listing()));
    CheckVector(*info, name);
    VarPtr var(Mat_VarRead(mat_, name.c_str()));
    if (!var || !var->data)
      throw InputError(fmt::format("{}: variable '{}' could not be read{}", path_, name, MatioDetail()));
    auto values = AsDoubleSamples(*var);
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        throw InputError(fmt::format("{}: variable '{}' sample {} is {}; every sample must be a finite number", path_,
                                     name, i + 1, values[i]));
    return values;
  }

 private:
  void CheckVector(const matvar_t& v, const std::string& name) const {
    const std::string what = fmt::format("{}: variable '{}' is a {} {} array", path_, name, Shape(v), ClassName(v));
    if (v.class_type == MAT_C_EMPTY && Elements(v) > 0)  // data, but no class libmatio recognises
      throw InputError(
          fmt::format("{}: variable '{}' ({}) has no MATLAB class that libmatio recognises; in a v7.3 "
                      "(HDF5) file every dataset needs a MATLAB_class attribute such as 'double', "
                      "written null-terminated as MATLAB writes it",
                      path_, name, Shape(v)));
    if (v.isLogical || !IsNumericClass(v.class_type))
      throw InputError(what + "; a recording variable must be numeric (double, single or integer)");
    if (v.isComplex) throw InputError(what + " of complex numbers; a recording variable must be real");
    const std::size_t n = Elements(v);
    if (n == 0) throw InputError(what + " with no elements; a recording variable needs at least one sample");
    int long_dims = 0;
    for (int k = 0; k < v.rank; ++k) long_dims += v.dims[k] > 1;
    if (long_dims > 1)
      throw InputError(what + "; a recording variable must be a vector (1xN or Nx1): store one signal per variable");
  }

  std::string path_;
  mat_t* mat_ = nullptr;
};

}  // namespace

CsvTable read_mat_columns(const std::string& path, const std::vector<MatColumn>& columns) {
  MatFile file(path);
  CsvTable table;
  table.source = path;
  std::string first;  // the variable that set the length, for the message
  for (const auto& c : columns) {
    auto values = file.ReadVector(c.variable);
    if (!table.columns.empty() && values.size() != table.rows())
      throw InputError(
          fmt::format("{}: variable '{}' has {} samples but '{}' has {}; the variables of one recording "
                      "must have the same length",
                      path, c.variable, values.size(), first, table.rows()));
    if (table.columns.empty()) first = c.variable;
    table.add_column(c.column, std::move(values));
  }
  return table;
}

std::vector<std::string> mat_variable_names(const std::string& path) {
  MatFile file(path);
  std::vector<std::string> names;
  for (const auto& v : file.Headers())
    if (v->name) names.emplace_back(v->name);
  return names;
}

}  // namespace hw
