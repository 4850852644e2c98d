#pragma once
// Text made safe for HTML and data: URIs.

#include <string>
#include <string_view>

namespace psq::reports {

/// Escapes &, <, >, " and ' as character references (safe in text and quoted attributes).
std::string escape_html(std::string_view text);

/// Standard base64 (RFC 4648, with '=' padding) of arbitrary bytes.
std::string base64(std::string_view bytes);

}  // namespace psq::reports
