#include "dwellfit/estimator/curves/figures.h"

#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>

#include "boost/algorithm/string/join.hpp"
#include "dwellfit/estimator/common/string_printf.h"

namespace dwellfit {
namespace {

std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string Preamble(const FigureSet& figures) {
  std::ostringstream gp;
  gp << "# Chapter-style figures of a dwellfit run; the data are in the datablocks of each\n"
        "# sweep. PNG: gnuplot figures.gp; SVG: gnuplot -e \"fmt='svg'\" figures.gp\n"
        "set encoding utf8\n"
        "if (!exists(\"fmt\")) fmt = \"png\"\n"
        "if (fmt eq \"svg\") {\n"
        "  set terminal svg size 900,760 dynamic noenhanced font \"sans,12\" background \"white\"\n"
        "} else {\n"
        "  set terminal pngcairo size 900,760 noenhanced font \"sans,10\"\n"
        "}\n"
        "set grid lc rgb \"#dddddd\"\n"
        "set key opaque box\n"
        "set style textbox opaque noborder\n";
  gp << "estimates = " << Quoted(boost::algorithm::join(figures.corner_lines, "\n")) << "\n";
  gp << "amplitude_unit = " << Quoted(figures.amplitude_unit) << "\n\n";
  return gp.str();
}

// A datablock of polylines (a blank line between two) named $<name>.
void AppendBlock(const std::string& name, const std::vector<FigureLine>& lines, std::string* gp) {
  *gp += "$" + name + " << EOD\n";
  for (size_t i = 0; i < lines.size(); ++i) {
    if (i > 0) *gp += "\n";
    for (const FigurePoint& p : lines[i]) {
      if (std::isfinite(p.x) && std::isfinite(p.y)) *gp += StringPrintf("%.9g %.9g\n", p.x, p.y);
    }
  }
  *gp += "EOD\n";
}

bool HasPoints(const std::vector<FigureLine>& lines) {
  return std::any_of(lines.begin(), lines.end(),
                     [](const FigureLine& line) { return !line.empty(); });
}

// One `plot` of the datablocks that have points: each element is
// {block name, lines, style and title}.
struct PlotElement {
  std::string block;
  std::vector<FigureLine> lines;
  std::string style;
};

std::string Plot(const std::string& prefix, const std::vector<PlotElement>& elements,
                 const std::string& extra) {
  std::string gp;
  std::vector<std::string> parts;
  for (const PlotElement& element : elements) {
    if (!HasPoints(element.lines)) continue;
    AppendBlock(prefix + element.block, element.lines, &gp);
    parts.push_back("$" + prefix + element.block + " using 1:2 " + element.style);
  }
  if (!extra.empty()) parts.push_back(extra);
  return gp + "plot " + boost::algorithm::join(parts, ", \\\n  ") + "\n";
}

std::string SweepFigure(const FigureSet& figures, const FigureSweep& s, size_t index) {
  const std::string prefix = "s" + std::to_string(index) + "_";
  const std::string title = s.id + " (" + s.role + "): " + SweepKindName(s.kind) + " sweep at " +
                            s.held + (s.notes.empty() ? "" : "\n") +
                            boost::algorithm::join(s.notes, "\n");
  const char* dwell_size = s.up.size() + s.down.size() > 400 ? "0.35" : "1.1";
  std::ostringstream gp;
  gp << "# " << s.id << " (" << s.role << "): " << SweepKindName(s.kind) << " sweep at " << s.held
     << "\n";
  gp << "set output \"" << FigureFileStem(s) << ".\".fmt\n";
  gp << "set multiplot\n"
        "set origin 0, 0.3\nset size 1, 0.7\nset lmargin 12\nset format x \"\"\nunset xlabel\n";
  gp << "set title " << Quoted(title) << "\n";
  gp << "set ylabel \"" << figures.amplitude_name << " [\".amplitude_unit.\"]\"\n"
     << (figures.log_amplitude ? "set logscale y\n" : "");
  // The key under the corner's lines (about 0.037 of the graph's height each).
  const double key_top = 0.93 - 0.037 * static_cast<double>(figures.corner_lines.size());
  gp << (s.kind == SweepKind::kFrequency
             ? StringPrintf("set key at graph 0.02, graph %.3f left top\n", key_top)
             : std::string("set key inside bottom right\n"));
  gp << "set label 1 estimates at graph 0.02, graph 0.96 left front boxed font \",9\"\n";
  for (size_t i = 0; i < s.jump_lines.size(); ++i) {
    gp << StringPrintf(
        "set arrow %zu from %.17g, graph 0 to %.17g, graph 1 nohead dt 3 lc rgb \"#888888\"\n",
        i + 1, s.jump_lines[i], s.jump_lines[i]);
  }
  const std::string up_style =
      std::string("with points pt 8 ps ") + dwell_size + " lc rgb \"#2ca02c\" title \"up dwells\"";
  const std::string down_style = std::string("with points pt 10 ps ") + dwell_size +
                                 " lc rgb \"#ff7f0e\" title \"down dwells\"";
  gp << Plot(prefix,
             {{"stable", s.stable, "with lines lw 2 lc rgb \"black\" title \"stable\""},
              {"unstable", s.unstable, "with lines lw 2 dt 2 lc rgb \"black\" title \"unstable\""},
              {"backbone",
               {s.backbone},
               std::string(s.kind == SweepKind::kFrequency ? "with lines dt 3"
                                                           : "with points pt 6 ps 1.5") +
                   " lc rgb \"#1f77b4\" title \"backbone\""},
              {"folds", {s.folds}, "with points pt 7 ps 1.3 lc rgb \"#d62728\" title \"folds\""},
              {"up", {s.up}, up_style},
              {"down", {s.down}, down_style}},
             s.jump_lines.empty()
                 ? ""
                 : "NaN with lines dt 3 lc rgb \"#888888\" title \"measured jump bracket\"");
  gp << "unset label 1\nunset arrow\nunset title\nunset logscale y\n";
  gp << "set origin 0, 0\nset size 1, 0.3\nset format x \"% h\"\n";
  gp << "set xlabel "
     << Quoted(s.kind == SweepKind::kFrequency
                   ? "drive frequency [Hz]"
                   : figures.level_name + " [" + figures.control_unit + "]")
     << "\nset ylabel " << Quoted(figures.residual_label) << "\nunset key\n";
  gp << Plot(prefix + "r",
             {{"up", {s.up_residual}, up_style}, {"down", {s.down_residual}, down_style}},
             "0 with lines lc rgb \"black\" notitle");
  gp << "unset multiplot\nset format x \"% h\"\nunset output\n\n";
  return gp.str();
}

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

// The number of distinct held values among the jumps of `kind`.
size_t HeldValues(const std::vector<OverviewJump>& overview, SweepKind kind) {
  std::vector<double> held;
  for (const OverviewJump& jump : overview) {
    if (jump.sweep_kind == kind) held.push_back(jump.held);
  }
  std::sort(held.begin(), held.end());
  return static_cast<size_t>(std::unique(held.begin(), held.end()) - held.begin());
}

// The rows of the overview's datablocks for one jump kind.
struct OverviewRows {
  std::string measured, model, band;
};
OverviewRows OverviewData(std::vector<OverviewJump> jumps) {
  std::sort(jumps.begin(), jumps.end(),
            [](const OverviewJump& a, const OverviewJump& b) { return a.held < b.held; });
  OverviewRows rows;
  for (const OverviewJump& j : jumps) {
    rows.measured +=
        StringPrintf("%.9g %.9g %.9g %.9g\n", j.held, 0.5 * (j.measured_low + j.measured_high),
                     j.measured_low, j.measured_high);
    if (std::isfinite(j.model)) rows.model += StringPrintf("%.9g %.9g\n", j.held, j.model);
    if (std::isfinite(j.band_low)) {
      rows.band += StringPrintf("%.9g %.9g %.9g %.9g\n", j.held, j.model, j.band_low, j.band_high);
    }
  }
  return rows;
}

// The overview of the jumps of `sweep_kind`: per jump kind, the measured
// brackets (error bars about their centres), the model's folds (a line over
// the held values) and the validation sweeps' 95 % prediction intervals.
std::string OverviewFigure(const FigureSet& figures, SweepKind sweep_kind) {
  const bool frequency = sweep_kind == SweepKind::kFrequency;
  const std::string level = figures.level_name + " [" + figures.control_unit + "]";
  const bool has_band =
      std::any_of(figures.overview.begin(), figures.overview.end(), [&](const OverviewJump& j) {
        return j.sweep_kind == sweep_kind && std::isfinite(j.band_low);
      });
  std::string gp =
      StringPrintf("# Where the sweeps jump\nset output \"%s.\".fmt\n", kOverviewFigureStem);
  gp += std::string("set title \"") +
        (frequency ? "Jump frequencies against the base level"
                   : "Jump levels against the drive frequency") +
        ": measured brackets and the model's folds" +
        (has_band ? ", with 95 % prediction intervals\"\n" : "\"\n");
  gp += "set xlabel " + Quoted(frequency ? level : "drive frequency [Hz]") + "\nset ylabel " +
        Quoted(frequency ? "jump frequency [Hz]" : "jump " + level) +
        "\nset key inside top left\nset format x \"% h\"\n"
        "set origin 0, 0\nset size 1, 1\nset offsets graph 0.03, graph 0.03, 0, 0\n";
  std::vector<std::string> parts;
  for (JumpKind kind : {JumpKind::kJumpDown, JumpKind::kJumpUp}) {
    std::vector<OverviewJump> jumps;
    for (const OverviewJump& jump : figures.overview) {
      if (jump.kind == kind && jump.sweep_kind == sweep_kind) jumps.push_back(jump);
    }
    const OverviewRows rows = OverviewData(jumps);
    const std::string name = JumpKindName(kind);
    const bool down = kind == JumpKind::kJumpDown;
    struct Element {
      const char* block;
      std::string rows, columns, style;
    };
    // The bands first, so that the model and the measurements lie on them.
    for (const Element& e :
         {Element{"band", rows.band, "1:2:3:4",
                  StringPrintf("with yerrorbars pt 0 lw 5 lc rgb \"%s\"",
                               down ? "#f2b8b8" : "#b8d4ee")},
          Element{"model", rows.model, "1:2",
                  StringPrintf("with linespoints pt 6 lw 2 lc rgb \"%s\"",
                               down ? "#d62728" : "#1f77b4")},
          Element{"measured", rows.measured, "1:2:3:4",
                  StringPrintf("with yerrorbars pt %d ps 0.8 lc rgb \"black\"", down ? 7 : 5)}}) {
      if (e.rows.empty()) continue;
      const std::string id = "$overview_" + name + "_" + e.block;
      gp += id + " << EOD\n" + e.rows + "EOD\n";
      parts.push_back(id + " using " + e.columns + " " + e.style + " title \"" + name + ", " +
                      e.block + "\"");
    }
  }
  return gp + "plot " + boost::algorithm::join(parts, ", \\\n  ") + "\nunset output\nset offsets\n";
}

// omega(a) and zeta(a) of the identified model, each over its 95 % band.
std::string ModalFigure(const FigureSet& figures) {
  std::string gp = "# Amplitude-dependent natural frequency and damping ratio\n$modal << EOD\n";
  for (const auto& row : figures.modal) {
    for (size_t i = 0; i < row.size(); ++i) gp += StringPrintf(i == 0 ? "%.9g" : " %.9g", row[i]);
    gp += "\n";
  }
  gp += StringPrintf("EOD\nset output \"%s.\".fmt\n", kModalFigureStem);
  gp +=
      "set origin 0, 0\nset size 1, 1\nset multiplot layout 2,1 title \"The identified "
      "model's natural frequency and damping ratio against the amplitude (95 % bands)\"\n"
      "unset logscale\nset key inside top left\nset format x \"% h\"\nset xlabel " +
      Quoted(
          "amplitude a [" +
          (figures.displacement_unit.empty() ? figures.amplitude_unit : figures.displacement_unit) +
          "]") +
      "\n";
  for (const auto& [column, label] :
       {std::pair{2, "natural frequency omega(a) [Hz]"}, std::pair{5, "damping ratio zeta(a)"}}) {
    gp += StringPrintf(
        "set ylabel \"%s\"\nplot $modal using 1:%d:%d with filledcurves fc rgb \"#c6dbef\" "
        "title \"95 %% band\", $modal using 1:%d with lines lw 2 lc rgb \"#1f77b4\" title "
        "\"identified\"\n",
        label, column + 1, column + 2, column);
  }
  return gp + "unset multiplot\nunset output\n";
}

}  // namespace

std::string FigureFileStem(const FigureSweep& sweep) {
  std::string stem = "figure_" + sweep.role + "_" + sweep.id;
  for (char& c : stem) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '_') c = '_';
  }
  return stem;
}

std::string GnuplotFigureScript(const FigureSet& figures) {
  std::string script = Preamble(figures);
  for (size_t i = 0; i < figures.sweeps.size(); ++i) {
    script += SweepFigure(figures, figures.sweeps[i], i);
  }
  if (!figures.modal.empty()) script += ModalFigure(figures);
  for (SweepKind kind : {SweepKind::kFrequency, SweepKind::kAmplitude}) {
    if (HeldValues(figures.overview, kind) >= 2) return script + OverviewFigure(figures, kind);
  }
  return script;
}

RenderedFigures RenderFigures(const std::vector<NamedFile>& inputs) {
  namespace fs = std::filesystem;
  RenderedFigures out;
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    out.warning =
        "gnuplot was not found on PATH, so no figures were drawn (install gnuplot-nox; "
        "figures.gp draws them later)";
    return out;
  }
  std::string pattern = (fs::temp_directory_path() / "dwellfit-figures-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    out.warning = "no temporary folder for gnuplot could be made in " +
                  fs::temp_directory_path().string() + "; no figures were drawn";
    return out;
  }
  const fs::path folder(pattern);
  for (const NamedFile& file : inputs) {
    std::ofstream(folder / file.first, std::ios::binary) << file.second;
  }
  // One gnuplot a format, the two side by side.
  auto run = [&folder](const std::string& format) {
    const std::string command = "cd '" + folder.string() + "' && gnuplot -e \"fmt='" + format +
                                "'\" " + kFigureScriptName + " > gnuplot-" + format + ".log 2>&1";
    return std::system(command.c_str());
  };
  std::future<int> svg = std::async(std::launch::async, run, "svg");
  const int png_status = run("png");
  const int svg_status = svg.get();
  for (const auto& [status, format] :
       {std::pair{png_status, "png"}, std::pair{svg_status, "svg"}}) {
    if (status != 0) {
      out.warning = "gnuplot failed, so no figures were drawn: " +
                    ReadFile(folder / ("gnuplot-" + std::string(format) + ".log"));
      fs::remove_all(folder);
      return out;
    }
  }
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string extension = entry.path().extension().string();
    if (extension == ".png" || extension == ".svg") {
      out.images.emplace_back(entry.path().filename().string(), ReadFile(entry.path()));
    }
  }
  std::sort(out.images.begin(), out.images.end());
  fs::remove_all(folder);
  out.rendered = true;
  return out;
}

}  // namespace dwellfit
