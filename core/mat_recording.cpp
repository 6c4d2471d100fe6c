#include "core/mat_recording.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>

#include <fmt/format.h>
#include <matio.h>

#include "core/mat_hdf5.hpp"
#include "core/mat_source.hpp"

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

MatVariable Describe(const matvar_t& v) {
  MatVariable out;
  out.name = v.name ? v.name : "?";
  for (int k = 0; k < v.rank; ++k) out.dims.push_back(v.dims[k]);
  // MAT_C_EMPTY with data: a class libmatio does not know.
  out.class_name = v.class_type == MAT_C_EMPTY && Elements(v) > 0 ? "" : ClassName(v);
  out.numeric = !v.isLogical && IsNumericClass(v.class_type);
  out.complex = v.isComplex;
  return out;
}

// A v4, v5 or v7 file, read by libmatio; closed on scope exit.
class MatioSource : public MatSource {
 public:
  explicit MatioSource(const std::string& path) : path_(path) {
    InstallMatioLog();
    matio_last_message.clear();
    mat_ = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
    if (!mat_)
      throw InputError(
          fmt::format("{}: not a MATLAB .mat file that libmatio can read (v4, v5, v7 or v7.3){}; "
                      "save it with MATLAB's save(...) or scipy.io.savemat",
                      path, MatioDetail()));
  }
  ~MatioSource() override { Mat_Close(mat_); }
  MatioSource(const MatioSource&) = delete;
  MatioSource& operator=(const MatioSource&) = delete;

  std::vector<MatVariable> Variables() override {
    std::vector<MatVariable> out;
    Mat_Rewind(mat_);
    while (matvar_t* v = Mat_VarReadNextInfo(mat_)) {
      VarPtr info(v);
      out.push_back(Describe(*info));
    }
    return out;
  }

  std::optional<MatVariable> Find(const std::string& name) override {
    VarPtr info(Mat_VarReadInfo(mat_, name.c_str()));
    matio_last_message.clear();
    if (!info) return std::nullopt;
    return Describe(*info);
  }

  std::vector<double> ReadDoubles(const MatVariable& v) override {
    VarPtr var(Mat_VarRead(mat_, v.name.c_str()));
    if (!var || !var->data)
      throw InputError(fmt::format("{}: variable '{}' could not be read{}", path_, v.name, MatioDetail()));
    return AsDoubleSamples(*var);
  }

 private:
  std::string path_;
  mat_t* mat_ = nullptr;
};

// The reader of the file's kind: libhdf5 for v7.3 (HDF5) files, libmatio for the others.
std::unique_ptr<MatSource> OpenMat(const std::string& path) {
  if (std::filesystem::is_directory(path))
    throw InputError(fmt::format("{}: is a directory; expected a MATLAB .mat file", path));
  if (!std::ifstream(path)) throw InputError(fmt::format("{}: cannot open file", path));
  if (IsHdf5File(path)) return OpenHdf5Mat(path);
  return std::make_unique<MatioSource>(path);
}

// "vir (300x1 double), qm (300x1 double)": what the file offers, for messages.
std::string Listing(MatSource& file) {
  std::string s;
  for (const auto& v : file.Variables())
    s += fmt::format("{}{} ({} {})", s.empty() ? "" : ", ", v.name, v.shape(),
                     v.class_name.empty() ? "unknown class" : v.class_name);
  return s.empty() ? "no variables" : s;
}

// A recording variable is a real, full, numeric vector with at least one sample; throws InputError naming
// what it is otherwise.
void CheckVector(const std::string& path, const MatVariable& v) {
  const std::string what = fmt::format("{}: variable '{}' is a {} {} array", path, v.name, v.shape(), v.class_name);
  if (v.class_name.empty())
    throw InputError(fmt::format("{}: variable '{}' ({}) has no MATLAB class that the reader recognises; a recording "
                                 "variable must be numeric (double, single or integer)",
                                 path, v.name, v.shape()));
  if (!v.numeric) throw InputError(what + "; a recording variable must be numeric (double, single or integer)");
  if (v.complex) throw InputError(what + " of complex numbers; a recording variable must be real");
  if (v.elements() == 0) throw InputError(what + " with no elements; a recording variable needs at least one sample");
  const auto long_dims = std::count_if(v.dims.begin(), v.dims.end(), [](std::size_t d) { return d > 1; });
  if (long_dims > 1)
    throw InputError(what + "; a recording variable must be a vector (1xN or Nx1): store one signal per variable");
}

// The variable's samples; throws InputError naming what is wrong with it.
std::vector<double> ReadVector(MatSource& file, const std::string& path, const std::string& name) {
  const auto v = file.Find(name);
  if (!v) throw InputError(fmt::format("{}: no variable '{}'; the file has: {}", path, name, Listing(file)));
  CheckVector(path, *v);
  auto values = file.ReadDoubles(*v);
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw InputError(fmt::format("{}: variable '{}' sample {} is {}; every sample must be a finite number", path,
                                   name, i + 1, values[i]));
  return values;
}

}  // namespace

std::size_t MatVariable::elements() const {
  std::size_t n = 1;
  for (const auto d : dims) n *= d;
  return dims.empty() ? 0 : n;
}

std::string MatVariable::shape() const {
  std::string s;
  for (std::size_t k = 0; k < dims.size(); ++k) s += (k ? "x" : "") + std::to_string(dims[k]);
  return s.empty() ? "0x0" : s;
}

CsvTable read_mat_columns(const std::string& path, const std::vector<MatColumn>& columns) {
  const auto file = OpenMat(path);
  CsvTable table;
  table.source = path;
  std::string first;  // the variable that set the length, for the message
  for (const auto& c : columns) {
    auto values = ReadVector(*file, path, c.variable);
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
  const auto file = OpenMat(path);
  std::vector<std::string> names;
  for (const auto& v : file->Variables()) names.push_back(v.name);
  return names;
}

}  // namespace hw
