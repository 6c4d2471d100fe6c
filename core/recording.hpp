#pragma once
// The one way every command names a recording (--data, --validate, --input, a plan's files, Python):
//   rec.csv                      CSV with a header; columns by name (core/csv_table.hpp)
//   rec.mat:u=vir,y=qm[,t=t]     MATLAB file (v4, v5, v7.3): the column u is the variable vir, y is qm, ...
//   rec.mat                      MATLAB file whose variables carry the column names (u, y, ...)
//   rec.csv:u=vir,y=qm           CSV whose columns vir and qm serve as u and y
// A path is a MATLAB file when it ends in ".mat" (any case); the text after "FILE.mat:" or "FILE.csv:" is
// the column map. Anything else is a CSV path as given.
#include <string>
#include <vector>

#include "core/csv_table.hpp"
#include "core/mat_recording.hpp"

namespace hw {

struct RecordingSpec {
  std::string path;
  bool mat = false;
  std::vector<MatColumn> map;  // column = variable (or source column, for CSV), in the order given
  static RecordingSpec Parse(const std::string& text);  // throws InputError on a malformed map
};

// Reads the recording named by `spec` with the columns a command uses: every `required` column must be
// there, `optional` ones may be. A map key outside required and optional is an error (it would be
// ignored otherwise), as is a required column that neither the map nor the file provides.
// A CSV keeps all its columns (mapped ones added under their new names); a .mat file gives only the
// columns asked for. The time column "t", when the command reads it and the recording has it, is checked
// with CheckTimeColumn (as long as the other columns and finite, as every column, and strictly increasing).
CsvTable read_recording(const std::string& spec, const std::vector<std::string>& required,
                        const std::vector<std::string>& optional = {});

// The time column `t` of a recording (read_recording's, or one built from arrays): strictly increasing.
// Throws InputError naming `source` (the file, or the argument), `what` (e.g. "variable 'time'",
// "column 't'", "t"), the sample (its file line when `lines` has it) and the two values.
void CheckTimeColumn(const std::vector<double>& t, const std::string& source, const std::string& what,
                     const std::vector<int>& lines = {});

// "u, y and optionally t": the columns a command reads, for messages.
std::string DescribeColumns(const std::vector<std::string>& required, const std::vector<std::string>& optional);

}  // namespace hw
