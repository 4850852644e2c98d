// HTML escaping, one-line escaping and base64 (RFC 4648 test vectors).

#include "reports/html_text.hpp"

#include <gtest/gtest.h>

namespace psq::reports {
namespace {

TEST(HtmlText, Base64MatchesTheRfc4648Vectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\xfe", 3)), "/wD+");
}

TEST(HtmlText, EscapesMarkupCharacters) {
  EXPECT_EQ(escape_html(R"(<a href="x">Tom & 'Jerry'</a>)"),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt;");
  EXPECT_EQ(escape_html("drapé 1e-3"), "drapé 1e-3");
}

TEST(HtmlText, OneLineEscapingReplacesTheSpecialCharacterAndLineBreaks) {
  EXPECT_EQ(one_line_escaped("a|b\r\nc", '|', "\\|"), "a\\|b  c");
  EXPECT_EQ(one_line_escaped("it's", '\'', "''"), "it''s");
  EXPECT_EQ(one_line_escaped("", '|', "x"), "");
}

}  // namespace
}  // namespace psq::reports
