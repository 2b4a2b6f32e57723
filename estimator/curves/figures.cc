#include "dwellfit/estimator/curves/figures.h"

#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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
  gp << "# Chapter-style figures of a dwellfit run, drawn from curves.csv and predictions.csv\n"
        "# (docs/outputs.md). PNG: gnuplot figures.gp; SVG: gnuplot -e \"fmt='svg'\" figures.gp\n"
        "set encoding utf8\n"
        "if (!exists(\"fmt\")) fmt = \"png\"\n"
        "if (fmt eq \"svg\") {\n"
        "  set terminal svg size 900,760 dynamic noenhanced font \"sans,12\" background \"white\"\n"
        "} else {\n"
        "  set terminal pngcairo size 900,760 noenhanced font \"sans,10\"\n"
        "}\n"
        "set datafile separator \",\"\n"
        "set datafile missing \"\"\n"
        "curves = \"curves.csv\"\n"
        "dwells = \"predictions.csv\"\n"
        "set grid lc rgb \"#dddddd\"\n"
        "set key opaque box\n";
  gp << "estimates = " << Quoted(boost::algorithm::join(figures.corner_lines, "\n")) << "\n";
  gp << "amplitude_unit = " << Quoted(figures.amplitude_unit) << "\n\n";
  return gp.str();
}

// The `using` expression selecting one sweep's rows of curves.csv.
std::string CurveRows(const FigureSweep& s, const std::string& condition, const char* x) {
  return StringPrintf("(strcol('sweep') eq %s && %s ? column('%s') : NaN):'a'",
                      Quoted(s.id).c_str(), condition.c_str(), x);
}

std::string DwellRows(const FigureSweep& s, const char* direction, const char* x, const char* y) {
  return StringPrintf(
      "(strcol('sweep') eq %s && strcol('direction') eq \"%s\" ? column('%s') : "
      "NaN):(%s)",
      Quoted(s.id).c_str(), direction, x, y);
}

std::string SweepFigure(const FigureSweep& s) {
  const char* x = s.kind == SweepKind::kFrequency ? "freq_hz" : "a_base";
  std::ostringstream gp;
  gp << "# " << s.id << " (" << s.role << "): " << SweepKindName(s.kind) << " sweep at " << s.held
     << "\n";
  gp << "set output \"" << FigureFileStem(s) << ".\".fmt\n";
  gp << "dwell_size = " << (s.dwells > 400 ? "0.35" : "1.1") << "\n";
  gp << "set multiplot\n"
        "set origin 0, 0.3\nset size 1, 0.7\nset lmargin 12\nset format x \"\"\nunset xlabel\n";
  gp << "set title "
     << Quoted(s.id + " (" + s.role + "): " + SweepKindName(s.kind) + " sweep at " + s.held)
     << "\n";
  gp << "set ylabel \"a [\".amplitude_unit.\"]\"\n";
  gp << (s.kind == SweepKind::kFrequency ? "set key at graph 0.02, graph 0.72 left top\n"
                                         : "set key bottom right\n");
  gp << "set label 1 estimates at graph 0.02, graph 0.96 left front font \",9\"\n";
  for (size_t i = 0; i < s.jump_lines.size(); ++i) {
    gp << StringPrintf(
        "set arrow %zu from %.17g, graph 0 to %.17g, graph 1 nohead dt 3 lc rgb "
        "\"#888888\"\n",
        i + 1, s.jump_lines[i], s.jump_lines[i]);
  }
  gp << "plot for [s=0:" << s.segments - 1 << "] curves using "
     << CurveRows(s,
                  "strcol('curve') eq \"response\" && column('segment') == s && "
                  "column('stable') == 1",
                  x)
     << " with lines lw 2 lc rgb \"black\" title (s == 0 ? \"stable\" : \"\"), \\\n"
     << "  for [s=0:" << s.segments - 1 << "] curves using "
     << CurveRows(s,
                  "strcol('curve') eq \"response\" && column('segment') == s && "
                  "column('stable') == 0",
                  x)
     << " with lines lw 2 dt 2 lc rgb \"black\" title (s == 0 ? \"unstable\" : \"\"), \\\n"
     << "  curves using " << CurveRows(s, "strcol('curve') eq \"backbone\"", x)
     << (s.kind == SweepKind::kFrequency ? " with lines dt 3" : " with points pt 6 ps 1.5")
     << " lc rgb \"#1f77b4\" title \"backbone\", \\\n"
     << "  curves using " << CurveRows(s, "strcol('fold') ne \"\"", x)
     << " with points pt 7 ps 1.3 lc rgb \"#d62728\" title \"folds\", \\\n"
     << "  dwells using " << DwellRows(s, "up", x, "column('a')")
     << " with points pt 8 ps dwell_size lc rgb \"#2ca02c\" title \"up dwells\", \\\n"
     << "  dwells using " << DwellRows(s, "down", x, "column('a')")
     << " with points pt 10 ps dwell_size lc rgb \"#ff7f0e\" title \"down dwells\"\n";
  gp << "unset label 1\nunset arrow\nunset title\n";
  gp << "set origin 0, 0\nset size 1, 0.3\nset format x \"% h\"\n";
  gp << "set xlabel "
     << Quoted(s.kind == SweepKind::kFrequency ? "drive frequency [Hz]" : "base level a_base")
     << "\nset ylabel \"a - a_model\"\nunset key\n";
  gp << "plot dwells using " << DwellRows(s, "up", x, "column('a') - column('a_model')")
     << " with points pt 8 ps dwell_size lc rgb \"#2ca02c\" notitle, \\\n"
     << "  dwells using " << DwellRows(s, "down", x, "column('a') - column('a_model')")
     << " with points pt 10 ps dwell_size lc rgb \"#ff7f0e\" notitle, 0 with lines lc rgb "
        "\"black\" notitle\n";
  gp << "unset multiplot\nset format x \"% h\"\nunset output\n\n";
  return gp.str();
}

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
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
  for (const FigureSweep& sweep : figures.sweeps) script += SweepFigure(sweep);
  return script;
}

RenderedFigures RenderFigures(const std::vector<NamedFile>& inputs) {
  namespace fs = std::filesystem;
  RenderedFigures out;
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    out.warning =
        "gnuplot was not found on PATH, so no figures were drawn (install gnuplot-nox; "
        "figures.gp beside the CSVs draws them later)";
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
  for (const char* format : {"png", "svg"}) {
    const std::string command = "cd '" + folder.string() + "' && gnuplot -e \"fmt='" + format +
                                "'\" " + kFigureScriptName + " > gnuplot.log 2>&1";
    if (std::system(command.c_str()) != 0) {
      out.warning = "gnuplot failed, so no figures were drawn: " + ReadFile(folder / "gnuplot.log");
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
