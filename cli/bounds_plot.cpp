#include "cli/bounds_plot.hpp"

#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "core/output_files.hpp"

namespace hw::cli {
namespace {

namespace fs = std::filesystem;

// A temporary directory, removed with everything in it when this goes out of scope.
class TempDir {
 public:
  TempDir() {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = fmt::format("{}/hwbounds_plot_XXXXXX", base && *base ? base : "/tmp");
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("--plot: cannot create a temporary directory in " + pattern);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Where v lies in [lo, hi] as a fraction (0 at lo, 1 at hi); "?" (gnuplot's missing value) when undefined.
std::string Fraction(double v, double lo, double hi) {
  if (!std::isfinite(v) || !(hi > lo)) return "?";
  return fmt::format("{:.9g}", (v - lo) / (hi - lo));
}

std::string Quoted(const std::string& text) { return "\"" + text + "\""; }

// One row per interval, the first parameter on top: row, box label, interval label, then positions in the prior
// box (lower, upper, truth) and within the interval (witnessed lower, witnessed upper, truth); with the exact set,
// then its interval in the prior box (10, 11), its label (12) and, within its interval, the inner hull (13, 14)
// and the truth (15).
std::string IntervalRows(const dss::BoundsSummary& s, const std::vector<double>& truth, const ExactPlotIntervals* exact) {
  std::string rows;
  const int n = static_cast<int>(s.intervals.size());
  for (int r = 0; r < n; ++r) {
    const auto& iv = s.intervals[r];
    const std::size_t k = std::find(s.parameter_names.begin(), s.parameter_names.end(), iv.name) - s.parameter_names.begin();
    const auto [blo, bhi] = s.box[k];
    const double lo = iv.lower.value, hi = iv.upper.value, t = truth.empty() ? NAN : truth[k];
    rows += fmt::format("{} {} {} {} {} {} {} {} {}", n - 1 - r,
                        Quoted(fmt::format("{} in [{:.6g}, {:.6g}]", iv.name, blo, bhi)),
                        Quoted(std::isfinite(lo) ? fmt::format("{} [{:.6g}, {:.6g}]", iv.name, lo, hi) : iv.name + " empty"),
                        Fraction(lo, blo, bhi), Fraction(hi, blo, bhi), Fraction(t, blo, bhi),
                        Fraction(iv.witnessed_lower.value_or(NAN), lo, hi),
                        Fraction(iv.witnessed_upper.value_or(NAN), lo, hi), Fraction(t, lo, hi));
    if (exact) {
      const auto [elo, ehi] = exact->outer[k];
      const auto [ilo, ihi] = exact->inner[k];
      rows += fmt::format(" {} {} {} {} {} {}", Fraction(elo, blo, bhi), Fraction(ehi, blo, bhi),
                          Quoted(fmt::format("{} [{:.6g}, {:.6g}]", iv.name, elo, ehi)), Fraction(ilo, elo, ehi),
                          Fraction(ihi, elo, ehi), Fraction(t, elo, ehi));
    }
    rows += "\n";
  }
  return rows;
}

// Every certified feasible point, once per plotted parameter: row, position in the box, position in the interval.
std::string PointRows(const dss::BoundsSummary& s) {
  std::string rows;
  const int n = static_cast<int>(s.intervals.size());
  for (const auto& p : s.feasible_points)
    for (int r = 0; r < n; ++r) {
      const auto& iv = s.intervals[r];
      const std::size_t k = std::find(s.parameter_names.begin(), s.parameter_names.end(), iv.name) - s.parameter_names.begin();
      if (k >= p.point.size()) continue;
      rows += fmt::format("{} {} {}\n", n - 1 - r, Fraction(p.point[k], s.box[k].first, s.box[k].second),
                          Fraction(p.point[k], iv.lower.value, iv.upper.value));
    }
  return rows.empty() ? "? ? ?\n" : rows;  // gnuplot refuses an empty file; one missing row draws nothing
}

std::string Script(const dss::BoundsSummary& s, bool with_truth, const std::string& terminal, bool with_exact) {
  const int n = static_cast<int>(s.intervals.size());
  const std::string title =
      s.invalidated() ? "model invalidated: every sign orthant proven empty"
                      : fmt::format("guaranteed intervals, horizon n = {}, {}{}", s.horizon, s.relaxation,
                                    with_exact ? "; and of the exact set D" : "");
  std::string gp = fmt::format(
      "set terminal {} size 1400,{} noenhanced\n"
      "set output 'plot.png'\n"
      "set datafile missing '?'\n"
      "set multiplot layout 1,2 title {}\n"
      "set yrange [-0.8:{}]\nset grid xtics\nset key below horizontal maxrows 2\n",
      terminal, 180 + 48 * n, Quoted(title), n - 0.2);
  const std::string outer_label = with_exact ? fmt::format("D^ss({}) interval", s.horizon) : "guaranteed interval";
  const std::string truth = with_truth ? ", 'intervals.dat' using 6:1 with points pt 13 ps 2 lc rgb '#d62728' title 'truth'" : "";
  const std::string exact_bar =
      with_exact ? ", '' using 10:($1-0.25):($11-$10):(0) with vectors nohead lw 7 lc rgb '#ff7f0e' title 'exact set D interval'"
                 : "";
  gp += "set title 'in the prior box (0: its lower edge, 1: its upper edge)'\nset xrange [-0.05:1.05]\n";
  gp += "plot 'intervals.dat' using (0):1:(1):(0):ytic(2) with vectors nohead lw 14 lc rgb '#dddddd' title 'prior box', "
        "'' using 4:1:($5-$4):(0) with vectors nohead lw 7 lc rgb '#1f77b4' title '" + outer_label + "', "
        "'' using 4:1 with points pt 5 ps 0.8 lc rgb '#1f77b4' notitle, "
        "'' using 5:1 with points pt 5 ps 0.8 lc rgb '#1f77b4' notitle" + exact_bar + ", "
        "'points.dat' using 2:($1+0.25) with points pt 7 ps 0.6 lc rgb '#2ca02c' title 'certified feasible points'" +
        truth + "\n";
  gp += "set key below vertical maxrows 3\n";  // one column: it fits the panel's width
  if (with_exact) {
    const std::string truth_in = with_truth ? ", 'intervals.dat' using 15:1 with points pt 13 ps 2 lc rgb '#d62728' title 'truth'" : "";
    gp += "set title 'within the intervals of D (0: lower, 1: upper end)'\nset xrange [-0.1:1.1]\n";
    gp += "plot 'intervals.dat' using (0):1:(1):(0):ytic(12) with vectors nohead lw 7 lc rgb '#ff7f0e' title 'exact set D interval (outer)', "
          "'' using 13:($1+0.25):($14-$13):(0) with vectors nohead lw 3 lc rgb '#2ca02c' title 'inner hull (points of D)'" +
          truth_in + "\n";
  } else {
    const std::string truth_in = with_truth ? ", 'intervals.dat' using 9:1 with points pt 13 ps 2 lc rgb '#d62728' title 'truth'" : "";
    gp += "set title 'within each interval (0: its lower end, 1: its upper end)'\nset xrange [-0.1:1.1]\n";
    gp += "plot 'intervals.dat' using (0):1:(1):(0):ytic(3) with vectors nohead lw 7 lc rgb '#1f77b4' title 'guaranteed interval', "
          "'' using 7:($1+0.25):($8-$7):(0) with vectors nohead lw 3 lc rgb '#2ca02c' title 'feasible points reach', "
          "'points.dat' using 3:($1+0.25) with points pt 7 ps 0.6 lc rgb '#2ca02c' notitle" +
          truth_in + "\n";
  }
  gp += "unset multiplot\n";
  return gp;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

std::string CheckPlotOutput(const std::string& path) {
  if (fs::path(path).extension() != ".png")
    throw InputError(fmt::format("--plot {}: the picture is a PNG file; give a name ending in .png", path));
  CheckOutputFile(path, "--plot");
  if (!GnuplotAvailable())
    throw InputError("--plot: gnuplot is not on the PATH; install it (Debian: apt-get install gnuplot-nox) or leave "
                     "out --plot");
  for (const char* terminal : {"pngcairo", "png"})
    if (GnuplotHasTerminal(terminal)) return terminal;
  throw InputError("--plot: this gnuplot has no PNG terminal (pngcairo or png); install gnuplot-nox or leave out --plot");
}

std::string RenderBoundsPlot(const dss::BoundsSummary& summary, const std::vector<double>& truth,
                             const std::string& terminal, const ExactPlotIntervals* exact) {
  const TempDir dir;
  OutputFiles inputs;
  inputs.Add((dir.path() / "intervals.dat").string(), IntervalRows(summary, truth, exact));
  inputs.Add((dir.path() / "points.dat").string(), PointRows(summary));
  inputs.Add((dir.path() / "plot.gp").string(), Script(summary, !truth.empty(), terminal, exact != nullptr));
  inputs.Commit();
  if (!RunGnuplot(dir.path().string(), "plot.gp").empty())
    throw std::runtime_error(fmt::format("--plot: gnuplot failed:\n{}", ReadFile(dir.path() / "plot.gp.log")));
  std::string png = ReadFile(dir.path() / "plot.png");
  if (png.empty()) throw std::runtime_error("--plot: gnuplot wrote no picture");
  return png;
}

}  // namespace hw::cli
