#include "dwellfit/estimator/studies/study_pages.h"

#include <cmath>
#include <optional>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace dwellfit {
namespace {

using ::testing::HasSubstr;

// select_model's page: the recommendation with its reason, every variant's
// scores as the report holds them (a missing score as "-"), and the whole
// Markdown, escaped.
TEST(StudyPages, ModelSelectionPageShowsTheRecommendationAndEveryVariant) {
  ModelSelectionReport report;
  report.config_path = "beam.yaml";
  report.rule = "the least held-out error";
  report.verdict = "it predicts the jumps best";
  VariantResult fixed, free;
  fixed.variant.delta = {0.0, "0"};
  free.variant.delta = {std::nullopt, "free"};
  fixed.free_parameters = 4;
  fixed.eligible = true;
  fixed.jump_down_hz = 3.5;
  fixed.jump_down_percent = 1.94;
  fixed.jump_up_percent = fixed.upper_branch_percent = std::nan("");
  free.free_parameters = 5;
  free.jump_down_percent = free.jump_up_percent = free.upper_branch_percent = std::nan("");
  report.variants = {fixed, free};
  report.recommended = 0;
  const std::string html = ModelSelectionToHtml(report, "| a | <b> |");
  EXPECT_THAT(html, HasSubstr("<div class=\"status ok\" id=\"status\"><b>recommended</b>: " +
                              fixed.variant.Name() + ". it predicts the jumps best</div>"));
  EXPECT_THAT(html, HasSubstr("<td>" + fixed.variant.Name() +
                              "</td><td>4</td><td>yes</td><td>3.5 Hz (1.94 %)</td><td>-</td>"));
  EXPECT_THAT(html, HasSubstr("<td>" + free.variant.Name() + "</td><td>5</td><td>no</td>"));
  EXPECT_THAT(html, HasSubstr("| a | &lt;b&gt; |"));

  report.recommended = -1;
  EXPECT_THAT(ModelSelectionToHtml(report, ""),
              HasSubstr("<div class=\"status bad\" id=\"status\"><b>no variant qualifies</b>"));
}

}  // namespace
}  // namespace dwellfit
