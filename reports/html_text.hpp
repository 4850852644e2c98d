#pragma once
// Text made safe for the report's formats: HTML, data: URIs, and one-line fields (gnuplot
// strings, Markdown table cells).

#include <string>
#include <string_view>

namespace psq::reports {

/// Escapes &, <, >, " and ' as character references (safe in text and quoted attributes).
std::string escape_html(std::string_view text);

/// `text` on one line with one special character escaped: each `special` becomes `escaped`,
/// each line break (\n or \r) a space.
std::string one_line_escaped(std::string_view text, char special, std::string_view escaped);

/// Standard base64 (RFC 4648, with '=' padding) of arbitrary bytes.
std::string base64(std::string_view bytes);

}  // namespace psq::reports
