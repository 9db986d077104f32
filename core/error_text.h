// Text from outside (a field, a line, a key, an argument) made safe and short for an error
// message: a 2 MB field or binary garbage shows as a few dozen escaped characters, a UTF-16
// file's NULs do not cut the message, and a byte-order mark is named instead of making two
// identical-looking strings differ.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace mmh {

// Printable ASCII and valid UTF-8 are kept; control characters, NUL, invalid UTF-8 and the
// byte-order mark are escaped (\xNN, \t, \uFEFF); anything past `max_chars` characters is cut
// and the full length said: "... (2000000 bytes in all)".
std::string EscapeForMessage(std::string_view text, std::size_t max_chars = 48);

// EscapeForMessage(text) between single quotes.
std::string Quote(std::string_view text, std::size_t max_chars = 48);

}  // namespace mmh
