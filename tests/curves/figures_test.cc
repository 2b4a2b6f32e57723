#include "dwellfit/estimator/curves/figures.h"

#include <stdlib.h>

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

TEST(Figures, FileStemsAreSafeNames) {
  FigureSweep sweep;
  sweep.id = "L0.040g/a b";
  sweep.role = "fitted";
  EXPECT_EQ(FigureFileStem(sweep), "figure_fitted_L0.040g_a_b");
}

}  // namespace
}  // namespace dwellfit
