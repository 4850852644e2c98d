// The HTML report in a real browser: headless Chromium (Debian's `chromium`, installed by
// scripts/setup.sh) loads the page from disk with no network, every plot image decodes, every
// shape picture is there, and a screenshot of the page is a real picture.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "reports/html_text.hpp"
#include "reports/report_fixture.hpp"
#include "reports/report_writer.hpp"
#include "support/run_process.hpp"
#include "support/test_paths.hpp"

namespace psq::reports {
namespace {

constexpr const char* kChromium = "/usr/bin/chromium";
/// Tall enough for the whole fixture page: the screenshot shows every plot and picture.
constexpr int kWindowHeight = 7000;

/// Runs headless Chromium (at most a minute) with a private profile.
test::ProcessResult chromium(const std::filesystem::path& profile,
                             std::vector<std::string> arguments) {
  std::vector<std::string> command = {"60",
                                      kChromium,
                                      "--headless",
                                      "--no-sandbox",
                                      "--disable-gpu",
                                      "--user-data-dir=" + profile.string(),
                                      "--hide-scrollbars"};
  command.insert(command.end(), arguments.begin(), arguments.end());
  return test::run_process("/usr/bin/timeout", command);
}

/// The value of `data-<name>="..."` in Chromium's DOM dump, or -1.
long dom_number(const std::string& dom, const std::string& name) {
  std::smatch match;
  if (!std::regex_search(dom, match, std::regex("data-" + name + "=\"(-?\\d+)\""))) return -1;
  return std::stol(match[1]);
}

/// A copy of the report with a script that records, once the page has loaded, how many images
/// it has and how many decoded, how many shape pictures with how many triangles, and how many
/// distinct colours the screenshot (given as a data: URI, so the canvas may read it) has.
std::string probe_page(const std::string& report, const std::string& screenshot_png) {
  const std::string script =
      R"(<img id="screenshot" style="display:none" src="data:image/png;base64,)" +
      base64(screenshot_png) + R"(">
<script>
window.addEventListener('load', () => {
  const body = document.body;
  const shot = document.getElementById('screenshot');
  const plots = [...document.images].filter(image => image !== shot);
  body.dataset.images = plots.length;
  body.dataset.decoded = plots.filter(image => image.complete && image.naturalWidth > 0).length;
  body.dataset.shapes = document.querySelectorAll('svg.shape').length;
  body.dataset.polygons = document.querySelectorAll('svg.shape polygon').length;
  const canvas = document.createElement('canvas');
  canvas.width = shot.naturalWidth;
  canvas.height = shot.naturalHeight;
  const context = canvas.getContext('2d');
  context.drawImage(shot, 0, 0);
  const pixels = context.getImageData(0, 0, canvas.width, canvas.height).data;
  const colours = new Set();
  for (let i = 0; i < pixels.length; i += 4)
    colours.add((pixels[i] << 16) | (pixels[i + 1] << 8) | pixels[i + 2]);
  body.dataset.screenshotWidth = canvas.width;
  body.dataset.colours = colours.size;
  // The first shape picture's region of the screenshot (the page is not scrolled, one CSS
  // pixel per screenshot pixel): its distinct colours and its pixels that are not white.
  const box = document.querySelector('svg.shape').getBoundingClientRect();
  const region = context.getImageData(Math.round(box.left), Math.round(box.top),
                                      Math.round(box.width), Math.round(box.height)).data;
  const pictureColours = new Set();
  let drawn = 0;
  for (let i = 0; i < region.length; i += 4) {
    pictureColours.add((region[i] << 16) | (region[i + 1] << 8) | region[i + 2]);
    if (region[i] < 240 || region[i + 1] < 240 || region[i + 2] < 240) ++drawn;
  }
  body.dataset.pictureColours = pictureColours.size;
  body.dataset.pictureDrawnPercent = Math.round(100 * drawn / (region.length / 4));
  body.dataset.pictureBottom = Math.round(box.bottom);
});
</script>
)";
  const auto end = report.rfind("</body>");
  return report.substr(0, end) + script + report.substr(end);
}

TEST(HtmlReportInChromium, ShowsEveryPlotAndPictureAndScreenshotsAsARealPage) {
  ASSERT_TRUE(std::filesystem::exists(kChromium))
      << kChromium << " is missing: run scripts/setup.sh (Debian package chromium)";
  const auto dir = test::fresh_temp_dir("html_chromium");
  const auto database = test::make_report_fixture(dir);
  const ReportOutcome outcome = write_report({database, "plates", dir / "report", "gnuplot"});

  const auto screenshot = dir / "report.png";
  const auto shot = chromium(dir / "profile",
                             {"--screenshot=" + screenshot.string(),
                              fmt::format("--window-size=1280,{}", kWindowHeight),
                              "file://" + outcome.page.string()});
  ASSERT_EQ(shot.exit_code, 0) << shot.errors;
  ASSERT_TRUE(std::filesystem::exists(screenshot)) << shot.errors;
  EXPECT_GT(std::filesystem::file_size(screenshot), 50'000u);  // a blank page is a few kB

  const auto probe = test::write_file(
      dir / "report" / "probe.html",
      probe_page(test::read_file(outcome.page), test::read_file(screenshot)));
  const auto dump = chromium(
      dir / "profile", {"--dump-dom", "--virtual-time-budget=10000", "file://" + probe.string()});
  ASSERT_EQ(dump.exit_code, 0) << dump.errors;
  // The same counts as the page's source (report_writer_test): 12 plots (2 of them job 1's
  // probes), 5 pictures of 8-, 32- and 128-triangle levels (job 1), 8 (job 2, level 0) and 8
  // plus a 2-triangle collider (job 3).
  EXPECT_EQ(dom_number(dump.output, "images"), 12);
  EXPECT_EQ(dom_number(dump.output, "decoded"), 12);
  EXPECT_EQ(dom_number(dump.output, "shapes"), 5);
  EXPECT_EQ(dom_number(dump.output, "polygons"),
            8 + 32 + 128 + 8 + 8 + test::kColliderTriangles);
  EXPECT_EQ(dom_number(dump.output, "screenshot-width"), 1280);
  EXPECT_GT(dom_number(dump.output, "colours"), 50);  // plots, shading, text: not one colour
  // The first picture (job 1, level 0: a bent 8-triangle plate) lies inside the screenshot and
  // is a shaded, coloured shape, not a blank or one-colour box.
  ASSERT_GT(dom_number(dump.output, "picture-bottom"), 0);
  ASSERT_LE(dom_number(dump.output, "picture-bottom"), kWindowHeight);
  EXPECT_GT(dom_number(dump.output, "picture-colours"), 8);
  EXPECT_GT(dom_number(dump.output, "picture-drawn-percent"), 15);
}

}  // namespace
}  // namespace psq::reports
