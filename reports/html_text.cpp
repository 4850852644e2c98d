#include "reports/html_text.hpp"

#include <cstdint>

namespace psq::reports {

std::string escape_html(std::string_view text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&#39;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::string one_line_escaped(std::string_view text, char special, std::string_view escaped) {
  std::string line;
  line.reserve(text.size());
  for (char c : text) {
    if (c == special)
      line += escaped;
    else if (c == '\n' || c == '\r')
      line += ' ';
    else
      line += c;
  }
  return line;
}

std::string base64(std::string_view bytes) {
  static constexpr std::string_view alphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string encoded;
  encoded.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    // Three bytes (zero-padded at the end) make 24 bits, written as four 6-bit digits.
    const std::size_t count = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t group = 0;
    for (std::size_t k = 0; k < 3; ++k)
      group = (group << 8) | (k < count ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k)
      encoded += k <= count ? alphabet[(group >> (18 - 6 * k)) & 63u] : '=';
  }
  return encoded;
}

}  // namespace psq::reports
