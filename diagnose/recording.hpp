#pragma once
// Recordings for the diagnosis: an input u, an output y and a time axis t, read from a CSV file with a
// header or from a MATLAB file (FILE.mat:u=VAR,y=VAR[,t=VAR], through core/recording.hpp). Only the used columns are read: other columns may be empty, non-numeric or unnamed (a
// trailing comma in the header is common in benchmark files). Column names may be given per file:
// "ident.csv:u=uEst,y=yEst[,t=time]".
#include <cstddef>
#include <string>
#include <vector>

namespace hw::diagnose {

struct Recording {
  std::string name;
  std::vector<double> t, u, y;
};

struct ColumnNames {
  std::string u = "u", y = "y", t = "t";
  bool t_required = false;  // true when the user named the time column explicitly
};

// A recording file and which of its columns are u, y and t (the defaults, overridden per file). Not a second
// recording spec: the generic FILE.mat/.csv:COLUMN=VARIABLE map is core/recording.hpp's RecordingSpec, which a
// .mat file's source is read through.
struct RecordingSource {
  std::string path;
  ColumnNames columns;
  // "FILE" or "FILE:u=NAME,y=NAME[,t=NAME]"; the names given override `defaults`. Throws InputError.
  static RecordingSource Parse(const std::string& text, const ColumnNames& defaults);
};

// Throws InputError naming the file, the line and the column on bad input: a used column missing or
// named twice, a non-numeric or non-finite cell in a used column, a time column that does not increase,
// or fewer than `min_samples` rows. Without a time column the sample index is used.
Recording ReadRecording(const RecordingSource& spec, std::size_t min_samples = 60);
Recording ParseRecording(const std::string& text, const std::string& source, const ColumnNames& columns,
                         std::size_t min_samples = 60);

// A recording from signals given in memory (Python): u, y (and t unless empty: then t is the sample index)
// equally long, t strictly increasing, at least 60 samples. Throws InputError naming `name` and `t_col`.
Recording MakeRecording(std::string name, std::vector<double> t, std::vector<double> u, std::vector<double> y,
                        const std::string& t_col = "t", std::size_t min_samples = 60);

// A sub-range [from, to) of a recording (t keeps the original values).
Recording Slice(const Recording& r, std::size_t from, std::size_t to, const std::string& name);

}  // namespace hw::diagnose
