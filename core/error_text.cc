#include "core/error_text.h"

namespace mmh {

namespace {

// Length of the valid UTF-8 sequence at the start of `text` (2 to 4 bytes, no overlong forms,
// no surrogates, at most U+10FFFF), or 0.
std::size_t Utf8SequenceLength(std::string_view text) {
  const auto b = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = b(0);
  std::size_t length = 0;
  unsigned min = 0;
  unsigned code = 0;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2, code = lead & 0x1F, min = 0x80;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3, code = lead & 0x0F, min = 0x800;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4, code = lead & 0x07, min = 0x10000;
  } else {
    return 0;
  }
  if (text.size() < length) return 0;
  for (std::size_t i = 1; i < length; ++i) {
    if ((b(i) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (b(i) & 0x3F);
  }
  if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  if (code == 0xFEFF) return 0;  // the byte-order mark is shown escaped (see below)
  return length;
}

}  // namespace

std::string EscapeForMessage(std::string_view text, std::size_t max_chars) {
  static const char* kHex = "0123456789ABCDEF";
  std::string out;
  std::size_t i = 0, shown = 0;
  while (i < text.size() && shown < max_chars) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
      ++i;
    } else if (c == '\t') {
      out += "\\t";
      ++i;
    } else if (c == '\r') {
      out += "\\r";
      ++i;
    } else if (c == '\n') {
      out += "\\n";
      ++i;
    } else if (text.substr(i).starts_with("\xEF\xBB\xBF")) {
      out += "\\uFEFF (a byte-order mark)";
      i += 3;
    } else if (const std::size_t length = Utf8SequenceLength(text.substr(i)); length > 0) {
      out.append(text.substr(i, length));
      i += length;
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
      ++i;
    }
    ++shown;
  }
  if (i < text.size()) {
    out += "... (" + std::to_string(text.size()) + " bytes in all)";
  }
  return out;
}

std::string Quote(std::string_view text, std::size_t max_chars) {
  return "'" + EscapeForMessage(text, max_chars) + "'";
}

}  // namespace mmh
