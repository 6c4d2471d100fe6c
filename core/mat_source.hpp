#pragma once
// The readers behind core/mat_recording.hpp: one per kind of .mat file, each describing its variables the same
// way, so that the checks of a recording variable (and their messages) are written once.
//   v4, v5, v7 files: libmatio (core/mat_recording.cpp)
//   v7.3 files (HDF5): libhdf5 (core/mat_hdf5.cpp), which reads what MATLAB writes and also what h5py writes
//                      (MATLAB_class as a variable-length string, no 512-byte MATLAB header, no MATLAB_class)
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace hw {

// One variable of a .mat file, as its header describes it (no data).
struct MatVariable {
  std::string name;
  std::vector<std::size_t> dims;  // MATLAB's order: rows, columns, ...
  // "double", "single", "int8" ... "uint64", "logical", "char", "cell", "struct", "sparse", ...; empty when the
  // file gives a class the reader does not recognise.
  std::string class_name;
  bool numeric = false;  // full real or complex data of class double, single or an integer class (not logical)
  bool complex = false;
  std::size_t elements() const;
  std::string shape() const;  // "40x1"; "0x0" without dimensions
};

class MatSource {
 public:
  virtual ~MatSource() = default;
  // Every variable, in file order.
  virtual std::vector<MatVariable> Variables() = 0;
  // The variable called `name`, or nothing.
  virtual std::optional<MatVariable> Find(const std::string& name) = 0;
  // The samples of a numeric, real variable (Find's result), converted to double; throws InputError when the
  // file's data cannot be read.
  virtual std::vector<double> ReadDoubles(const MatVariable& variable) = 0;
};

}  // namespace hw
