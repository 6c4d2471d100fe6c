#include "core/mat_recording.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>

#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <matio.h>
#include <nlohmann/json.hpp>

#include "core/mat_hdf5.hpp"
#include "core/mat_layout.hpp"
#include "core/mat_source.hpp"
#include "core/worker_process.hpp"

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

struct MatClose {
  void operator()(mat_t* m) const { Mat_Close(m); }
};

// A v4, v5 or v7 file, read by libmatio once its layout is checked (core/mat_layout.hpp); closed on scope exit.
class MatioSource : public MatSource {
 public:
  explicit MatioSource(const std::string& path) : path_(path) {
    InstallMatioLog();
    matio_last_message.clear();
    // Without a v5 or v7.3 header libmatio reads the file as v4, and allocates what a v4 header claims.
    if (const int header = MatHeaderVersion(path); header != MAT_FT_MAT5 && header != MAT_FT_MAT73)
      CheckMatV4Layout(path);
    mat_.reset(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
    if (!mat_)
      throw InputError(
          fmt::format("{}: not a MATLAB .mat file that libmatio can read (v4, v5, v7 or v7.3){}; "
                      "save it with MATLAB's save(...) or scipy.io.savemat",
                      path, MatioDetail()));
    if (Mat_GetVersion(mat_.get()) == MAT_FT_MAT5) CheckMatV5Layout(path);
  }

  std::vector<MatVariable> Variables() override {
    std::vector<MatVariable> out;
    Mat_Rewind(mat_.get());
    while (matvar_t* v = Mat_VarReadNextInfo(mat_.get())) {
      VarPtr info(v);
      out.push_back(Describe(*info));
    }
    return out;
  }

  std::optional<MatVariable> Find(const std::string& name) override {
    VarPtr info(Mat_VarReadInfo(mat_.get(), name.c_str()));
    matio_last_message.clear();
    if (!info) return std::nullopt;
    return Describe(*info);
  }

  std::vector<double> ReadDoubles(const MatVariable& v) override {
    VarPtr var(Mat_VarRead(mat_.get(), v.name.c_str()));
    if (!var || !var->data)
      throw InputError(fmt::format("{}: variable '{}' could not be read{}", path_, v.name, MatioDetail()));
    return AsDoubleSamples(*var);
  }

 private:
  std::string path_;
  std::unique_ptr<mat_t, MatClose> mat_;
};

// The reader of the file's kind: libhdf5 for v7.3 (HDF5) files, libmatio for the others.
std::unique_ptr<MatSource> OpenMat(const std::string& path) {
  if (std::filesystem::is_directory(path))
    throw InputError(fmt::format("{}: is a directory; expected a MATLAB .mat file", path));
  if (!std::ifstream(path)) throw InputError(fmt::format("{}: cannot open file", path));
  if (IsHdf5File(path)) return OpenHdf5Mat(path);
  // libmatio would open it with libhdf5 itself, whose failures on such a file it does not report.
  if (MatHeaderVersion(path) == MAT_FT_MAT73)
    throw InputError(fmt::format("{}: a MATLAB v7.3 header without the HDF5 data that must follow it: the file is "
                                 "damaged or cut short; save it again",
                                 path));
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

void WriteAll(int fd, const std::string& text) {
  for (std::size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n <= 0) return;  // the parent reports the short answer
    done += static_cast<std::size_t>(n);
  }
}

std::string ReadAll(int fd) {
  std::string text;
  char buffer[65536];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

// The text a reading child sends back: {"value": ...}, {"input_error": message} or {"error": message}. Never
// throws (the child must not return into the caller's code); bytes of the file in a message that are not UTF-8
// are replaced.
std::string ChildAnswer(const std::function<nlohmann::json()>& work) {
  try {
    nlohmann::json answer;
    try {
      answer = {{"value", work()}};
    } catch (const InputError& e) {
      answer = {{"input_error", e.what()}};
    } catch (const std::exception& e) {
      answer = {{"error", e.what()}};
    }
    return answer.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  } catch (...) {
    return R"({"error": "the reading process failed"})";
  }
}

// Runs `work` on the file in a forked child and returns its answer. libhdf5 and libmatio can crash on a damaged
// file (libhdf5 1.10 segfaults in H5Gget_info on some: tests/parser_fuzz_test.cpp); in a child, a crash is
// reported as a damaged file instead of ending the process. An InputError of `work` is rethrown as it was.
nlohmann::json InChildProcess(const std::string& path, const std::function<nlohmann::json()>& work) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(fmt::format("{}: pipe: {}", path, std::strerror(errno)));
  const pid_t parent = ::getpid();
  const pid_t child = ::fork();
  if (child < 0) throw std::runtime_error(fmt::format("{}: fork: {}", path, std::strerror(errno)));
  if (child == 0) {
    ::close(fds[0]);
    EndWithParent(parent);
    WriteAll(fds[1], ChildAnswer(work));
    ::_exit(0);
  }
  ::close(fds[1]);
  const std::string text = ReadAll(fds[0]);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status))
    throw InputError(fmt::format("{}: the MATLAB file reader crashed on this file (signal {}): the file is damaged; "
                                 "save it again (MATLAB's save, scipy.io.savemat)",
                                 path, WTERMSIG(status)));
  const auto answer = nlohmann::json::parse(text, nullptr, false);
  if (answer.is_discarded() || !answer.is_object())
    throw std::runtime_error(fmt::format("{}: the reading process ended without an answer", path));
  if (answer.contains("input_error")) throw InputError(answer.at("input_error").get<std::string>());
  if (answer.contains("error")) throw std::runtime_error(answer.at("error").get<std::string>());
  return answer.at("value");
}

CsvTable ReadColumns(const std::string& path, const std::vector<MatColumn>& columns) {
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
  // The samples come back as JSON numbers, which keep every bit of a finite double.
  const auto j = InChildProcess(path, [&] {
    const CsvTable t = ReadColumns(path, columns);
    return nlohmann::json{{"names", t.names}, {"columns", t.columns}};
  });
  CsvTable table;
  table.source = path;
  const auto names = j.at("names").get<std::vector<std::string>>();
  auto values = j.at("columns").get<std::vector<std::vector<double>>>();
  for (std::size_t k = 0; k < names.size(); ++k) table.add_column(names[k], std::move(values[k]));
  return table;
}

std::vector<std::string> mat_variable_names(const std::string& path) {
  return InChildProcess(path, [&] {
           std::vector<std::string> names;
           for (const auto& v : OpenMat(path)->Variables()) names.push_back(v.name);
           return nlohmann::json(names);
         })
      .get<std::vector<std::string>>();
}

}  // namespace hw
