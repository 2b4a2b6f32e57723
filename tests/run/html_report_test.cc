#include "dwellfit/estimator/run/html_report.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dwellfit/config/identify_config.h"
#include "dwellfit/estimator/common/string_printf.h"
#include "dwellfit/estimator/run/identify_run.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

// docs/model.md, Units: each parameter's unit from those of a and a_base.
TEST(HtmlReport, ParameterUnitsFollowTheDataUnits) {
  const DataUnits units{"mm", "g"};
  EXPECT_EQ(ParameterUnit(ModelForm{}, kEtaE, units), "mm/(g s^2)");
  EXPECT_EQ(ParameterUnit(ModelForm{}, kMu1, units), "1/s");
  EXPECT_EQ(ParameterUnit(ModelForm{}, kMu2, units), "1/(mm s)");
  EXPECT_EQ(ParameterUnit(ModelForm{}, kDelta, units), "1/mm^2");
  EXPECT_EQ(ParameterUnit(ModelForm{}, kAlpha, units), "1/(mm^2 s^2)");
  EXPECT_EQ(ParameterUnit(ModelForm{}, kNaturalFrequency, units), "rad/s");
  EXPECT_EQ(ParameterUnit(ModelForm{}, kMu2, DataUnits{}), "1/([A] s)");
  // The family's terms (docs/model.md, "Terms beyond the chapter's"):
  // 2 mu3 u^2 u' and alpha5 u^5 are accelerations, as mu1 u' and w^2 u are.
  ModelForm family;
  family.damping = DampingTerm::kCubic;
  family.backbone = BackboneTerm::kQuintic;
  EXPECT_EQ(ParameterUnit(family, kMu3, units), "1/(mm^2 s)");
  EXPECT_EQ(ParameterUnit(family, kAlpha5, units), "1/(mm^4 s^2)");
  EXPECT_EQ(ParameterUnit(family, kAlpha, units), "1/(mm^2 s^2)");
}

TEST(HtmlReport, EscapesEveryMarkupCharacter) {
  EXPECT_EQ(HtmlEscape("<a href=\"x\">Tom & 'Jerry'</a>"),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt;");
}

// Text from the user (the config's path, a status message) cannot become
// markup; a run without figures says why it has none.
TEST(HtmlReport, ShowsUserTextAsTextAndSaysWhyThereAreNoFigures) {
  IdentificationReport report;
  report.config_path = "/data/<script>alert(1)</script>.yaml";
  report.result.status = FitStatus::kNoConvergence;
  report.result.message = "stopped after 200 iterations & the cost < 1";
  report.options.fixed[kMu2] = true;
  const std::string html = ReportToHtml(report, {}, "gnuplot was not found");
  EXPECT_THAT(html, Not(HasSubstr("<script>")));
  EXPECT_THAT(html, HasSubstr("&lt;script&gt;alert(1)&lt;/script&gt;"));
  EXPECT_THAT(html, HasSubstr("<div class=\"status bad\" id=\"status\"><b>no_convergence</b>: "
                              "stopped after 200 iterations &amp; the cost &lt; 1</div>"));
  EXPECT_THAT(html, HasSubstr("No figures: gnuplot was not found"));
  EXPECT_THAT(html, HasSubstr("<td>mu2</td><td>1/([A] s)</td><td class=\"n\">0</td><td "
                              "class=\"n\">-</td><td class=\"n\">-</td><td>fixed</td>"));
}

// identify writes report.html beside result.yaml, listed in the manifest, with
// the estimates and intervals result.yaml holds and every figure inline.
TEST(HtmlReport, IdentifyWritesTheReportWithItsFiguresInline) {
  const fs::path dir = fs::path(::testing::TempDir()) / "html_report_thesis";
  fs::remove_all(dir);
  const IdentifyConfig config =
      LoadIdentifyConfig(std::string(DWELLFIT_SOURCE_DIR) + "/datasets/thesis-numerical/beam.yaml",
                         {{"output_dir", dir.string(), "--test"}});
  std::ostringstream printed;
  const std::unique_ptr<IdentifyOutcome> outcome = RunIdentify(config, printed);
  std::ifstream in(dir / kHtmlReportName);
  std::stringstream text;
  text << in.rdbuf();
  const std::string html = text.str();
  std::ifstream manifest(dir / "manifest.yaml");
  std::stringstream listed;
  listed << manifest.rdbuf();
  EXPECT_THAT(listed.str(), HasSubstr(kHtmlReportName));
  const IdentificationReport& report = outcome->report;
  EXPECT_THAT(html, HasSubstr("<b>converged</b>"));
  EXPECT_THAT(html, HasSubstr(StringPrintf("<td>eta_e</td><td>[A]/([B] s^2)</td><td "
                                           "class=\"n\">%.10g</td>",
                                           report.result.parameters[kEtaE])));
  EXPECT_THAT(html, HasSubstr(StringPrintf("[%.6g, %.6g]", report.uncertainty.ci95_low[kMu1],
                                           report.uncertainty.ci95_high[kMu1])));
  int svg_files = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    svg_files += entry.path().extension() == ".svg";
  }
  EXPECT_GE(svg_files, 5);
  size_t inline_svgs = 0;
  for (size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at + 1)) {
    ++inline_svgs;
  }
  EXPECT_EQ(inline_svgs, static_cast<size_t>(svg_files));
  EXPECT_THAT(html, Not(HasSubstr("<?xml")));
  EXPECT_THAT(html, Not(HasSubstr("<script")));
}

}  // namespace
}  // namespace dwellfit
