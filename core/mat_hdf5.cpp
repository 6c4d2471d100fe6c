#include "core/mat_hdf5.hpp"

#include <hdf5.h>

#include <algorithm>
#include <mutex>

#include <fmt/format.h>

#include "core/input_error.hpp"

namespace hw {
namespace {

// libhdf5 prints its error stack on stderr by default; the reader reports errors itself (the deepest
// description of the stack is added to its messages).
void SilenceHdf5ErrorStack() {
  static std::once_flag once;
  std::call_once(once, [] { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); });
}

herr_t CollectDescription(unsigned /*n*/, const H5E_error2_t* e, void* out) {
  if (e && e->desc && *e->desc) *static_cast<std::string*>(out) = e->desc;
  return 0;
}

// " (libhdf5: ...)" from the current error stack (which is cleared), or "".
std::string Hdf5Detail() {
  std::string deepest;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, CollectDescription, &deepest);
  H5Eclear2(H5E_DEFAULT);
  return deepest.empty() ? "" : " (libhdf5: " + deepest + ")";
}

// An HDF5 identifier, closed on scope exit.
class Id {
 public:
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Id() {
    if (id_ >= 0) close_(id_);
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Longest attribute string or link name read: far beyond MATLAB's (63-character names, class names); a longer
// one comes from a damaged size field, whose claim is not allocated.
constexpr std::size_t kMaxNameBytes = 4096;

bool IsMatlabNumericClass(const std::string& c) {
  static const char* const kNames[] = {"double", "single", "int8",  "uint8",  "int16", "uint16",
                                       "int32",  "uint32", "int64", "uint64"};
  return std::find(std::begin(kNames), std::end(kNames), c) != std::end(kNames);
}

// The single string value of an attribute, however it is stored: fixed-length (null-terminated, null-padded
// or space-padded) or variable-length, ASCII or UTF-8. Nothing when the attribute is absent or not a string.
std::optional<std::string> StringAttribute(hid_t object, const char* name) {
  if (H5Aexists(object, name) <= 0) return std::nullopt;
  const Id attr(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
  const Id type(H5Aget_type(attr.get()), H5Tclose);
  const Id space(H5Aget_space(attr.get()), H5Sclose);
  if (!type.ok() || H5Tget_class(type.get()) != H5T_STRING || H5Sget_simple_extent_npoints(space.get()) != 1)
    return std::nullopt;
  std::string value;
  if (H5Tis_variable_str(type.get()) > 0) {
    const Id memory(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memory.get(), H5T_VARIABLE);
    H5Tset_cset(memory.get(), H5Tget_cset(type.get()));
    char* text = nullptr;
    if (H5Aread(attr.get(), memory.get(), &text) < 0) return std::nullopt;
    if (text) value = text;
    H5Dvlen_reclaim(memory.get(), space.get(), H5P_DEFAULT, &text);
  } else {
    const std::size_t size = H5Tget_size(type.get());
    if (size == 0 || size > kMaxNameBytes) return std::nullopt;
    std::string buffer(size, '\0');
    if (H5Aread(attr.get(), type.get(), buffer.data()) < 0) return std::nullopt;
    value = buffer.substr(0, buffer.find('\0'));
    value.erase(value.find_last_not_of(' ') + 1);
  }
  return value;
}

// The unsigned integer value of an attribute (MATLAB_empty, MATLAB_sparse), or nothing.
std::optional<unsigned long long> IntegerAttribute(hid_t object, const char* name) {
  if (H5Aexists(object, name) <= 0) return std::nullopt;
  const Id attr(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
  const Id space(H5Aget_space(attr.get()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) return std::nullopt;
  unsigned long long value = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_ULLONG, &value) < 0) return std::nullopt;
  return value;
}

// MATLAB's dimensions of an HDF5 dataspace: the HDF5 dimensions reversed (MATLAB is column-major); a scalar is
// 1x1 and a one-dimensional dataset of N (as h5py writes a numpy vector) is Nx1.
std::vector<std::size_t> MatlabDims(hid_t space) {
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank <= 0) return {1, 1};
  std::vector<hsize_t> h5(rank);
  H5Sget_simple_extent_dims(space, h5.data(), nullptr);
  std::vector<std::size_t> dims(h5.rbegin(), h5.rend());
  if (dims.size() == 1) dims.push_back(1);
  return dims;
}

// A compound type of two members "real" and "imag" (as MATLAB stores complex numbers) or "r" and "i" (as h5py
// stores numpy's).
bool IsComplexType(hid_t type) {
  if (H5Tget_class(type) != H5T_COMPOUND || H5Tget_nmembers(type) != 2) return false;
  std::string names[2];
  for (unsigned k = 0; k < 2; ++k) {
    char* name = H5Tget_member_name(type, k);
    names[k] = name ? name : "";
    H5free_memory(name);
  }
  return (names[0] == "real" && names[1] == "imag") || (names[0] == "r" && names[1] == "i");
}

// The class a dataset without a MATLAB_class attribute has by its HDF5 type.
std::string ClassOfType(hid_t type) {
  const std::size_t bits = 8 * H5Tget_size(type);
  switch (H5Tget_class(type)) {
    case H5T_FLOAT: return bits == 64 ? "double" : bits == 32 ? "single" : fmt::format("float{}", bits);
    case H5T_INTEGER: return fmt::format("{}int{}", H5Tget_sign(type) == H5T_SGN_NONE ? "u" : "", bits);
    case H5T_ENUM: return H5Tget_nmembers(type) == 2 ? "logical" : "enum";  // h5py stores numpy bools as an enum
    case H5T_STRING: return "string";
    case H5T_COMPOUND: {
      if (!IsComplexType(type)) return "compound";
      const Id part(H5Tget_member_type(type, 0), H5Tclose);  // the class of the real and imaginary parts
      return ClassOfType(part.get());
    }
    case H5T_REFERENCE: return "reference";
    default: return "non-numeric HDF5";
  }
}

bool IsNumericType(hid_t type) {
  const H5T_class_t c = H5Tget_class(type);
  return c == H5T_FLOAT || c == H5T_INTEGER || IsComplexType(type);
}

// A dataset: its class from MATLAB_class (or its type), its dimensions, MATLAB's empty arrays (whose data are
// their dimensions, marked by MATLAB_empty).
MatVariable DescribeDataset(hid_t dataset, const std::string& name) {
  MatVariable v;
  v.name = name;
  const Id type(H5Dget_type(dataset), H5Tclose);
  const Id space(H5Dget_space(dataset), H5Sclose);
  const auto matlab_class = StringAttribute(dataset, "MATLAB_class");
  v.class_name = matlab_class ? *matlab_class : ClassOfType(type.get());
  v.complex = IsComplexType(type.get());
  // Without the attribute, ClassOfType names numeric types double, single, intN, uintN (and floatN).
  const bool numeric_class =
      IsMatlabNumericClass(v.class_name) || (!matlab_class && v.class_name.rfind("float", 0) == 0);
  v.numeric = numeric_class && IsNumericType(type.get());
  v.dims = MatlabDims(space.get());
  if (IntegerAttribute(dataset, "MATLAB_empty").value_or(0) != 0) v.dims = {0, 0};
  return v;
}

// A group: a struct, a sparse array (MATLAB_sparse holds its rows; jc has one entry per column and one more),
// or a plain HDF5 group.
MatVariable DescribeGroup(hid_t group, const std::string& name) {
  MatVariable v;
  v.name = name;
  v.dims = {1, 1};
  if (const auto rows = IntegerAttribute(group, "MATLAB_sparse")) {
    v.class_name = "sparse";
    std::size_t columns = 0;
    if (H5Lexists(group, "jc", H5P_DEFAULT) > 0) {
      const Id jc(H5Dopen2(group, "jc", H5P_DEFAULT), H5Dclose);
      const Id space(H5Dget_space(jc.get()), H5Sclose);
      const auto n = H5Sget_simple_extent_npoints(space.get());
      columns = n > 0 ? static_cast<std::size_t>(n - 1) : 0;
    }
    v.dims = {static_cast<std::size_t>(*rows), columns};
    return v;
  }
  v.class_name = StringAttribute(group, "MATLAB_class").value_or("group");
  return v;
}

class Hdf5Source : public MatSource {
 public:
  explicit Hdf5Source(const std::string& path)
      : path_(path), file_(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose) {
    if (!file_.ok())
      throw InputError(fmt::format("{}: an HDF5 file that libhdf5 cannot open{}; save it again with MATLAB's "
                                   "save(..., '-v7.3'), h5py or scipy.io.savemat",
                                   path, Hdf5Detail()));
  }

  std::vector<MatVariable> Variables() override {
    std::vector<MatVariable> out;
    for (const auto& name : LinkNames())
      if (auto v = Find(name)) out.push_back(std::move(*v));
    return out;
  }

  // Variables are the objects in the root group; names MATLAB cannot give a variable ("#refs#", where MATLAB
  // keeps the contents of cells, and paths into groups) are not variables.
  std::optional<MatVariable> Find(const std::string& name) override {
    if (name.empty() || name[0] == '#' || name.find('/') != std::string::npos) return std::nullopt;
    if (H5Lexists(file_.get(), name.c_str(), H5P_DEFAULT) <= 0) return std::nullopt;
    const Id object(H5Oopen(file_.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
    if (!object.ok()) return std::nullopt;  // e.g. a link to nowhere
    switch (H5Iget_type(object.get())) {
      case H5I_DATASET: return DescribeDataset(object.get(), name);
      case H5I_GROUP: return DescribeGroup(object.get(), name);
      default: return std::nullopt;  // a named datatype
    }
  }

  std::vector<double> ReadDoubles(const MatVariable& v) override {
    const Id dataset(H5Dopen2(file_.get(), v.name.c_str(), H5P_DEFAULT), H5Dclose);
    if (!dataset.ok()) throw InputError(fmt::format("{}: variable '{}' could not be read{}", path_, v.name, Hdf5Detail()));
    CheckStoredSize(dataset.get(), v);
    std::vector<double> values(v.elements());
    if (H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
      throw InputError(fmt::format("{}: variable '{}' could not be read{}", path_, v.name, Hdf5Detail()));
    return values;
  }

 private:
  // The root group's link names in name order (HDF5 files from h5py keep no creation order).
  std::vector<std::string> LinkNames() const {
    H5G_info_t info;
    if (H5Gget_info(file_.get(), &info) < 0) return {};
    std::vector<std::string> names;
    for (hsize_t i = 0; i < info.nlinks; ++i) {
      const ssize_t size =
          H5Lget_name_by_idx(file_.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
      if (size < 0 || static_cast<std::size_t>(size) > kMaxNameBytes) continue;
      std::string name(static_cast<std::size_t>(size) + 1, '\0');
      H5Lget_name_by_idx(file_.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT);
      name.resize(static_cast<std::size_t>(size));
      names.push_back(std::move(name));
    }
    return names;
  }

  // The samples a dataset's dimensions claim are stored in the file (a damaged dimension would make the reader
  // allocate what it claims): without filters in at least that many bytes (chunks may hold more), deflated in at
  // most 1032 times fewer (zlib's largest ratio).
  void CheckStoredSize(hid_t dataset, const MatVariable& v) const {
    const Id type(H5Dget_type(dataset), H5Tclose);
    const Id plist(H5Dget_create_plist(dataset), H5Pclose);
    const double needed = static_cast<double>(v.elements()) * static_cast<double>(H5Tget_size(type.get()));
    const double stored = static_cast<double>(H5Dget_storage_size(dataset));
    const bool filtered = plist.ok() && H5Pget_nfilters(plist.get()) > 0;
    if (filtered ? needed > 1032.0 * stored : needed > stored)
      throw InputError(fmt::format("{}: damaged variable '{}': it is {} {} ({} bytes) but the file stores {} bytes of "
                                   "its data; save the file again",
                                   path_, v.name, v.shape(), v.class_name, needed, stored));
  }

  std::string path_;
  Id file_;
};

}  // namespace

bool IsHdf5File(const std::string& path) {
  SilenceHdf5ErrorStack();
  const bool hdf5 = H5Fis_hdf5(path.c_str()) > 0;
  H5Eclear2(H5E_DEFAULT);
  return hdf5;
}

std::unique_ptr<MatSource> OpenHdf5Mat(const std::string& path) {
  SilenceHdf5ErrorStack();
  return std::make_unique<Hdf5Source>(path);
}

}  // namespace hw
