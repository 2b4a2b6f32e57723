#include "dwellfit/estimator/curves/figures.h"

#include <stdlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// identify writes curves.csv, figures.gp and, drawn by gnuplot (installed by
// cmake/install-debian-deps.sh, so required here), a PNG and an SVG per sweep.
TEST(Figures, IdentifyDrawsAValidPngAndSvgPerSweep) {
  const fs::path dir = fs::path(::testing::TempDir()) / "figures_thesis";
  fs::remove_all(dir);
  const IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml",
                         {{"output_dir", dir.string(), "--test"}});
  std::ostringstream printed;
  RunIdentify(config, printed);
  EXPECT_THAT(printed.str(), ::testing::Not(HasSubstr("warning: gnuplot")));

  const std::string png = ReadFile(dir / "figure_fitted_F0.01.png");
  ASSERT_GT(png.size(), 10000u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  EXPECT_EQ(png.substr(png.size() - 8, 4), "IEND");

  const std::string svg = ReadFile(dir / "figure_validation_A41.8.svg");
  ASSERT_GT(svg.size(), 10000u);
  EXPECT_THAT(svg, HasSubstr("<svg"));
  EXPECT_THAT(svg, HasSubstr("</svg>"));
  EXPECT_THAT(svg, HasSubstr("A41.8 (validation): amplitude sweep at 41.8 Hz"));
  EXPECT_THAT(svg, HasSubstr("eta_e = 100"));
  // The corner names its intervals and the run's status; the residual axis
  // is the fit's error measure (the thesis config fits the relative error).
  EXPECT_THAT(svg, HasSubstr("estimate [95 % interval, gauss_newton]"));
  EXPECT_THAT(svg, HasSubstr("status: converged"));
  EXPECT_THAT(svg, HasSubstr("ln a - ln a_model"));
  EXPECT_THAT(svg, HasSubstr("measured jump bracket"));
  EXPECT_THAT(svg, HasSubstr("from the bracket centre"));
  // Three amplitude sweeps at three drive frequencies: the overview.
  EXPECT_THAT(ReadFile(dir / "figure_overview_jumps.svg"),
              HasSubstr("Jump levels against the drive frequency"));

  // Every file is in the manifest, the script and the curves beside them.
  const std::string manifest = ReadFile(dir / "manifest.yaml");
  for (const char* name : {"curves.csv", "figures.gp", "figure_fitted_A41.5.png",
                           "figure_fitted_A41.5.svg", "figure_validation_A41.2.png"}) {
    EXPECT_THAT(manifest, HasSubstr(name));
  }
  EXPECT_THAT(ReadFile(dir / "curves.csv"),
              HasSubstr("sweep,kind,curve,segment,freq_hz,a_base,a,stable,fold,phase_deg\n"));

  // A run without figures into the same folder leaves none of the old ones.
  IdentifyRunOptions no_figures;
  no_figures.render_figures = false;
  RunIdentify(config, printed, no_figures);
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename().string().rfind("figure_", 0), std::string::npos)
        << entry.path();
  }
  EXPECT_TRUE(fs::exists(dir / "figures.gp"));
}

TEST(Figures, AFailingScriptIsAWarningNotAnError) {
  const RenderedFigures rendered = RenderFigures({{kFigureScriptName, "plot 'absent.csv'\n"}});
  EXPECT_FALSE(rendered.rendered);
  EXPECT_THAT(rendered.warning, HasSubstr("gnuplot failed"));
  EXPECT_TRUE(rendered.images.empty());
}

TEST(Figures, AMissingGnuplotIsAWarningNotAnError) {
  const char* path = std::getenv("PATH");
  const std::string saved = path != nullptr ? path : "";
  setenv("PATH", "/nonexistent-dwellfit-test", 1);
  const RenderedFigures rendered = RenderFigures({{kFigureScriptName, "print 1\n"}});
  setenv("PATH", saved.c_str(), 1);
  EXPECT_FALSE(rendered.rendered);
  EXPECT_THAT(rendered.warning, HasSubstr("gnuplot was not found"));
  EXPECT_TRUE(rendered.images.empty());
}

// The script carries each sweep's points in datablocks of its own: a blank
// line between two lines of a branch, non-finite points left out, and a set
// without points neither written nor plotted.
TEST(Figures, EachSweepsPointsAreInItsOwnDatablocks) {
  FigureSet figures;
  figures.residual_label = "a - a_model [mm]";
  FigureSweep sweep;
  sweep.id = "F1";
  sweep.role = "fitted";
  sweep.held = "a_base = 1";
  sweep.stable = {{{10, 1}, {11, 2}}, {{13, 0.5}, {14, 0.25}}};
  sweep.up = {{10, 1.5}, {12, std::nan("")}};
  sweep.up_residual = {{10, 0.5}};
  figures.sweeps = {sweep, sweep};
  figures.sweeps[1].id = "F2";
  const std::string script = GnuplotFigureScript(figures);
  EXPECT_THAT(script, HasSubstr("$s0_stable << EOD\n10 1\n11 2\n\n13 0.5\n14 0.25\nEOD\n"));
  EXPECT_THAT(script, HasSubstr("$s0_up << EOD\n10 1.5\nEOD\n"));
  EXPECT_THAT(script, HasSubstr("$s0_rup << EOD\n10 0.5\nEOD\n"));
  EXPECT_THAT(script, HasSubstr("$s1_stable << EOD\n"));
  EXPECT_THAT(script, HasSubstr("set ylabel \"a - a_model [mm]\""));
  EXPECT_THAT(script, ::testing::Not(HasSubstr("$s0_unstable")));
  EXPECT_THAT(script, ::testing::Not(HasSubstr("$s0_down")));
  EXPECT_THAT(script, ::testing::Not(HasSubstr(".csv")));
  EXPECT_THAT(script, ::testing::Not(HasSubstr("\nset logscale y")));
  figures.log_amplitude = true;  // the amplitude panels only
  const std::string log_script = GnuplotFigureScript(figures);
  EXPECT_THAT(log_script, HasSubstr("set logscale y\n"));
  EXPECT_LT(log_script.find("set logscale y"), log_script.find("$s0_rup"));
  EXPECT_LT(log_script.find("unset logscale y"), log_script.find("$s0_rup"));

  // gnuplot draws it with nothing beside it.
  const RenderedFigures rendered = RenderFigures({{kFigureScriptName, script}});
  ASSERT_TRUE(rendered.rendered) << rendered.warning;
  ASSERT_EQ(rendered.images.size(), 4u);
  EXPECT_EQ(rendered.images[0].first, "figure_fitted_F1.png");
  EXPECT_EQ(rendered.images[3].first, "figure_fitted_F2.svg");
}

// The overview draws the frequency sweeps' jumps against their levels once
// two levels have them: the measured brackets about their centres, the
// model's folds and the prediction intervals, each in its own datablock.
TEST(Figures, TheOverviewDrawsJumpsAgainstTheLevel) {
  const double nan = std::nan("");
  FigureSet figures;
  figures.control_unit = "g";
  figures.overview = {
      {SweepKind::kFrequency, 0.08, JumpKind::kJumpDown, 194.0, 195.0, 194.6, nan, nan},
      {SweepKind::kFrequency, 0.04, JumpKind::kJumpDown, 168.0, 169.0, 170.0, 160.0, 180.0},
      {SweepKind::kAmplitude, 41.5, JumpKind::kJumpUp, 0.03, 0.04, 0.035, nan, nan}};
  std::string script = GnuplotFigureScript(figures);
  EXPECT_THAT(script, HasSubstr("set output \"figure_overview_jumps.\".fmt"));
  EXPECT_THAT(script, HasSubstr("Jump frequencies against the base level"));
  EXPECT_THAT(script, HasSubstr("with 95 % prediction intervals"));
  // Sorted by level; the bracket's centre, low and high.
  EXPECT_THAT(script, HasSubstr("$overview_jump_down_measured << EOD\n0.04 168.5 168 169\n"
                                "0.08 194.5 194 195\nEOD\n"));
  EXPECT_THAT(script, HasSubstr("$overview_jump_down_model << EOD\n0.04 170\n0.08 194.6\nEOD\n"));
  EXPECT_THAT(script, HasSubstr("$overview_jump_down_band << EOD\n0.04 170 160 180\nEOD\n"));
  EXPECT_THAT(script, HasSubstr("base level a_base [g]"));
  EXPECT_THAT(script, ::testing::Not(HasSubstr("jump_up")));  // the amplitude sweep's one level
  const RenderedFigures rendered = RenderFigures({{kFigureScriptName, script}});
  ASSERT_TRUE(rendered.rendered) << rendered.warning;
  ASSERT_EQ(rendered.images.size(), 2u);
  EXPECT_EQ(rendered.images[0].first, "figure_overview_jumps.png");

  // One level: no overview.
  figures.overview.pop_back();
  figures.overview.pop_back();
  script = GnuplotFigureScript(figures);
  EXPECT_THAT(script, ::testing::Not(HasSubstr("overview")));
}

TEST(Figures, FileStemsAreSafeNames) {
  FigureSweep sweep;
  sweep.id = "L0.040g/a b";
  sweep.role = "fitted";
  EXPECT_EQ(FigureFileStem(sweep), "figure_fitted_L0.040g_a_b");
}

}  // namespace
}  // namespace dwellfit
