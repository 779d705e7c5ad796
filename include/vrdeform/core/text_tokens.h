#pragma once
// Whitespace-separated tokens of a text file, with line numbers, for the hand-written readers of the
// text mesh formats. Every failure throws vrd::Error naming the file and the line.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace vrd::io {

/// The whole file; throws vrd::Error when it is missing, not a regular file or unreadable.
std::string readFileBytes(const std::filesystem::path& path);

/// At most 24 characters of `text` for a message, bytes other than printable ASCII shown as \xNN:
/// what a broken file holds may be binary garbage.
std::string printable(std::string_view text);

/// Whitespace as the C locale's isspace has it (space, \t, \n, \r, \v, \f), without its locale.
constexpr bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

/// The words of one line, separated by spaces, tabs, \r, \v or \f, in order (into `words`, cleared first).
void splitWords(std::string_view line, std::vector<std::string_view>& words);

/// Parses all of `token` as a decimal integer or a real number (C locale); false when it is not one.
bool parseInteger(std::string_view token, std::int64_t& value);
bool parseReal(std::string_view token, double& value);

class TextTokens {
 public:
  /// `comment`: a character that starts a comment running to the end of the line ('\0': none).
  /// `firstLine`: the line `text` starts on, when it is part of a larger file.
  TextTokens(std::string_view text, std::string name, char comment = '\0', std::size_t firstLine = 1);

  /// True when only whitespace and comments remain.
  bool atEnd();
  /// The next token without consuming it; empty at the end.
  std::string_view peek();
  /// The next token; throws at the end of the file, saying that `expected` was.
  std::string_view next(std::string_view expected);
  std::int64_t integer(std::string_view what);
  /// An integer in [lo, hi]; anything else throws, naming `what`.
  std::int64_t integer(std::string_view what, std::int64_t lo, std::int64_t hi);
  double real(std::string_view what);
  /// A real number that a float holds: beyond +-3.4e38 throws "... out of range for a float".
  float real32(std::string_view what);
  /// `value` (parsed from `token`) as a float, or the same error.
  float toFloat(double value, std::string_view token, std::string_view what) const;
  /// A count of items that take at least `tokensPerItem` tokens each. Throws when it is negative or when
  /// the rest of the file is too short to hold that many, so that a header claiming 10^12 elements is
  /// rejected before anything is reserved.
  std::size_t count(std::string_view what, std::size_t tokensPerItem);
  /// The check behind count(), for a count whose item size was only known later.
  void checkFits(std::uint64_t n, std::string_view what, std::size_t tokensPerItem);
  /// Skips the rest of the current line and its newline.
  void skipLine();
  /// The rest of the current line (without its newline), consumed.
  std::string_view restOfLine();

  /// Throws vrd::Error "name:line: message" at the line of the last token read.
  [[noreturn]] void fail(std::string_view message) const;

  const std::string& name() const { return name_; }
  std::size_t line() const { return tokenLine_; }
  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return text_.size() - pos_; }
  std::string_view text() const { return text_; }
  /// Moves past `bytes` bytes of binary data (the caller checked that they exist); lines are not counted.
  void skipBytes(std::size_t bytes) { pos_ += bytes; }

 private:
  void skipSpace();
  std::pair<double, std::string_view> realToken(std::string_view what);

  std::string_view text_;
  std::string name_;
  char comment_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;       // line at pos_
  std::size_t tokenLine_ = 1;  // line of the last token
};

}  // namespace vrd::io
